// Calibration of the whole sensor suite, as stored in a dataset's calibration.yaml.
//
// Frames: body B = IMU frame (x forward, y right, z down). Every sensor S has T_B_S.
// Noise figures are continuous-time densities for the IMU (Kalibr / EuRoC names and units) and
// 1-sigma values for the others.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct ImuCalibration {
  std::string name = "imu0";
  Pose3 T_B_S;  // identity: B is the IMU frame
  double rate_hz = 200.0;
  double gyroscope_noise_density = 3.4e-4;      // rad/s/sqrt(Hz)
  double gyroscope_random_walk = 3.9e-5;        // rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 4.0e-3;  // m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 6.0e-3;    // m/s^3/sqrt(Hz)
  // Full scale per axis: a reading beyond it is no measurement (a corrupt sample, a driver
  // error) and is skipped. Defaults: +-2000 deg/s and +-16 g, the widest ranges of common MEMS
  // IMUs; set the sensor's own (calibration.yaml imu: gyroscope_range, accelerometer_range).
  double gyroscope_range = 34.9;        // rad/s
  double accelerometer_range = 156.9;   // m/s^2
};

struct DepthCalibration {
  std::string name = "depth0";
  Pose3 T_B_S;
  double rate_hz = 10.0;
  double sigma_m = 0.02;
};

// An AHRS or compass (HeadingMeasurement): its heading of the x axis of S (T_B_S's rotation;
// its position does not matter), with 1-sigma sigma_rad. The dock's own heading in the same
// reference is dock.yaml's heading_deg.
struct HeadingCalibration {
  std::string name = "ahrs0";
  Pose3 T_B_S;
  double rate_hz = 10.0;
  double sigma_rad = 0.035;  // 2 degrees: a magnetic heading near a steel dock
};

struct DvlCalibration {
  std::string name = "dvl0";
  Pose3 T_B_S;
  double rate_hz = 5.0;
  double sigma_mps = 0.01;
};

struct AcousticCalibration {
  std::string name = "usbl0";
  Pose3 T_B_S;  // position of the vehicle's acoustic transducer
  double rate_hz = 1.0;
  double sigma_min_m = 0.05;          // floor of the 1-sigma error
  double sigma_range_fraction = 0.005;  // 1-sigma grows as this fraction of slant range
};

// A short-baseline (SBL) array (seed 001): transducers on the hull, each ranging to the dock's
// beacon (dock.yaml beacon_p_D). Seed 001's four transducers are the corners of an a x b
// rectangle in the hull's bottom plane.
struct SblCalibration {
  std::string name = "sbl0";
  std::vector<Eigen::Vector3d> p_B_transducers;  // each transducer's position in B (m)
  double rate_hz = 2.0;                // pings per second
  double sigma_min_m = 0.02;           // floor of a range's 1-sigma error
  double sigma_range_fraction = 0.002;  // 1-sigma grows as this fraction of the range
};

struct Calibration {
  std::vector<CameraCalibration> cameras;
  std::optional<ImuCalibration> imu;
  std::optional<DepthCalibration> depth;
  std::optional<DvlCalibration> dvl;
  std::optional<HeadingCalibration> heading;
  std::optional<AcousticCalibration> acoustic;
  std::optional<SblCalibration> sbl;

  const CameraCalibration* FindCamera(const std::string& name) const;
  const CameraCalibration* FindCameraByRole(CameraRole role) const;
};

// calibration.yaml <-> Calibration. Load throws InputError naming the file and key.
Calibration LoadCalibration(const std::string& path);
void SaveCalibration(const Calibration& calibration, const std::string& path);

}  // namespace auvdock
