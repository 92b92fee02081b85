// Sensor records as stored in a dataset. Time is int64 nanoseconds; frames as named.
//
//   ImuSample         gyro w_B (rad/s) and specific force f_B (m/s^2) of the IMU, body frame B
//                     (B is the IMU frame). f_B = R_B_D (a_D - g_D) + noise + bias.
//   DepthMeasurement  depth below the surface (m) of the pressure sensor.
//   DvlMeasurement    velocity of the DVL over the ground in the DVL frame S (m/s).
//   AcousticFix       position of the vehicle's transducer in D (m) and its reported 1-sigma.
//   SblRange          short-baseline (SBL) slant range (m) from the dock's beacon to one of the
//                     transducers on the hull (seed 001), and its reported 1-sigma.
//   CameraFrame       one image: timestamp and file path (absolute, or relative to the
//                     camera folder's data/ directory as written in data.csv).
//   GroundTruthState  EuRoC state ground truth: T_D_B, v_D (m/s), gyro and accel biases.
//   VisibilityRecord  per camera frame: how many dock lights each camera truly sees and the
//                     visibility stage of seed 000 (stereo only / both / mono only / neither).
//   FaultRecord       a fault injected by the simulator on purpose (for evaluation).
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct ImuSample {
  int64_t t_ns = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s^2 (specific force)
};

struct DepthMeasurement {
  int64_t t_ns = 0;
  double depth_m = 0.0;
};

// An AHRS's or compass's heading of its x axis: the angle about the downward vertical, clockwise
// seen from above, from the heading reference (north, magnetic or true) to the axis's horizontal
// part (rad, any branch).
struct HeadingMeasurement {
  int64_t t_ns = 0;
  double heading_rad = 0.0;
};

struct DvlMeasurement {
  int64_t t_ns = 0;
  Eigen::Vector3d v_S = Eigen::Vector3d::Zero();
};

struct AcousticFix {
  int64_t t_ns = 0;  // when the vehicle's position was measured
  Eigen::Vector3d p_D = Eigen::Vector3d::Zero();
  double sigma_m = 0.0;
  // From the measurement to its arrival on the vehicle (an acoustic fix is computed ashore or
  // on the dock and sent back: 0.2-1 s late). A causal estimator may use it from arrival_t_ns().
  int64_t latency_ns = 0;
  int64_t arrival_t_ns() const { return t_ns + latency_ns; }
};

// One slant range of a short-baseline ping: each transducer of the hull's array times the
// beacon's reply on its own, so a ping gives up to one range per transducer (fewer when some
// had no reply: no row for them).
struct SblRange {
  int64_t t_ns = 0;     // when the ping was measured (the vehicle measures it: no latency)
  int transducer = 0;   // index into SblCalibration::p_B_transducers
  double range_m = 0.0;
  double sigma_m = 0.0;
};

struct CameraFrame {
  int64_t t_ns = 0;
  std::string path;
};

struct GroundTruthState {
  int64_t t_ns = 0;
  Pose3 T_D_B;
  Eigen::Vector3d v_D = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
};

// Seed 000's four visibility stages. A camera "sees" the dock when at least kMinLightsForPose
// lights are in its image (for the stereo pair: in both images).
enum class VisibilityStage { kStereoOnly, kBoth, kMonoOnly, kNeither, kUnknown };
constexpr int kMinLightsForPose = 3;
const char* VisibilityStageName(VisibilityStage stage);
bool ParseVisibilityStage(const std::string& text, VisibilityStage* stage);
VisibilityStage StageFromLightCounts(int n_stereo_left, int n_stereo_right, int n_mono);

struct VisibilityRecord {
  int64_t t_ns = 0;
  int n_stereo_left = 0;
  int n_stereo_right = 0;
  int n_mono = 0;
  VisibilityStage stage = VisibilityStage::kUnknown;
};

// Where a light truly is in one camera image (the simulator's ground truth for a detector).
struct LightTruth {
  int light_id = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // distorted projection of the light's centre
  double range_m = 0.0;
  double sigma_px = 0.0;  // drawn blob's sigma
  double peak = 0.0;      // luma amplitude above the background, gray levels (> 255: saturated)
};

struct FaultRecord {
  int64_t t_ns = 0;
  std::string sensor;  // e.g. "dvl0", "usbl0", "cam2"
  std::string kind;    // e.g. "gross_error", "outlier", "reflection", "particle"
  std::string detail;  // free text without commas, e.g. "dv=0.41;0.02;-0.10"
};

}  // namespace auvdock
