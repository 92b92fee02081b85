// A simulation scenario (data/scenarios/*.yaml): the dock, the trajectory, the sensor rig and
// its noise, the water and the faults to inject. Every key has a default (the defaults are the
// built-in default scenario, with sensor figures from CONVENTIONS.md); unknown keys are errors.
//
// Frames: D dock (z down), B body = IMU (x forward, y right, z down), C camera (OpenCV).
// The stereo pair looks forward and down (tilted by tilt_deg below the body x axis), the mono
// camera straight down (image top towards the bow), as in seed 004's rig.
#pragma once

#include <cstdint>
#include <string>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/sim/acoustic_simulator.h"
#include "auvdock/sim/depth_simulator.h"
#include "auvdock/sim/sbl_simulator.h"
#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/dvl_simulator.h"
#include "auvdock/sim/imu_simulator.h"
#include "auvdock/sim/render_look.h"
#include "auvdock/sim/synthetic_detections.h"
#include "auvdock/sim/underwater_renderer.h"
#include "auvdock/sim/water_model.h"

namespace auvdock {

struct CameraRigConfig {
  int width = 640;
  int height = 512;
  double rate_hz = 10.0;
  double hfov_deg = 70.0;
  std::array<double, 5> distortion{-0.05, 0.01, 0.0005, -0.0003, 0.0};
  double pixel_noise_px = 0.3;
  double stereo_baseline_m = 0.25;
  double stereo_tilt_deg = 45.0;                                  // below the body x axis
  Eigen::Vector3d stereo_p_B = Eigen::Vector3d(0.9, 0.0, 0.2);    // midpoint of the pair
  Eigen::Vector3d mono_p_B = Eigen::Vector3d(0.75, 0.0, 0.3);
  // Cameras not synchronised with each other: the mono camera's frames are this long after the
  // stereo pair's (s, in [0, 1 / rate_hz)); 0 = one trigger for all three.
  double mono_time_offset_s = 0.0;
  // false: no images; each camera's detections are drawn instead (sim/synthetic_detections.h)
  // into detections.csv, for `run` / `smooth --detections` (seconds instead of a minute).
  bool render_images = true;
  SyntheticDetectionConfig synthetic_detections;  // key synthetic_detections
};

struct Scenario {
  std::string name = "default";
  std::string source_path;  // the YAML file it was read from ("" for built-in)
  double duration_s = 40.0;
  int64_t start_time_ns = 1700000000000000000;  // 2023-11-14T22:13:20Z, a realistic epoch
  uint64_t seed = 1;
  bool noise_enabled = true;  // false: every sensor exact (tests)

  DockModel dock;
  std::string dock_path;  // as written in the scenario (resolved relative to it)
  DockingTrajectoryConfig trajectory;
  CameraRigConfig cameras;
  WaterType water_type = WaterType::kCoastal;
  RenderOptions render;
  RenderRandomization randomize;  // the images' domain randomisation, off by default

  ImuCalibration imu;
  ImuErrorConfig imu_errors;  // scenario key imu.errors: what the estimator does not model
  Eigen::Vector3d initial_gyro_bias = Eigen::Vector3d(0.002, -0.001, 0.0015);   // rad/s
  Eigen::Vector3d initial_accel_bias = Eigen::Vector3d(0.03, -0.02, 0.04);      // m/s^2
  DepthCalibration depth;
  DepthFaultConfig depth_faults;  // scenario keys depth.bias_m, depth.bias_rate_mps
  DvlCalibration dvl;
  DvlFaultConfig dvl_faults;
  AcousticCalibration acoustic;
  AcousticFaultConfig acoustic_faults;
  // An AHRS or compass (scenario key `heading:` {rate_hz, sigma_deg, yaw_deg: its x axis's turn
  // from the body's about z}), absent unless the scenario has one (sim/heading_simulator.h).
  std::optional<HeadingCalibration> heading;
  // A short-baseline array (scenario key `sbl:`), absent unless the scenario has one.
  std::optional<SblCalibration> sbl;
  SblFaultConfig sbl_faults;
};

// Reads a scenario file; the dock file it names is read relative to the scenario's folder.
// Throws InputError naming the file and key.
Scenario LoadScenario(const std::string& path);

// The calibration of the simulated rig (what the dataset's calibration.yaml holds). With
// randomize.strong_distortion, each camera's distortion is drawn from the seed (render_look.h).
Calibration MakeCalibration(const Scenario& scenario);

// Multiplies every fault rate by factor (>= 0; probabilities clamped to 1): DVL spikes and
// bias episodes, acoustic and SBL outliers and SBL dropouts, and the synthetic front-end's misses, spurious blobs and
// wrong ids (`simulate --fault-scale`, the Monte-Carlo audit's "several times the default").
// The sizes of the faults and the image renderer's distractors are unchanged.
void ScaleFaultRates(double factor, Scenario* scenario);

}  // namespace auvdock
