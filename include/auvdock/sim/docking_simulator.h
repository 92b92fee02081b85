// The deterministic docking simulator: samples the trajectory, every sensor and the cameras of
// a Scenario, and writes a dataset folder (docs/dataset_format.md) with ground truth.
//
// Time base: sample k of a sensor at rate f is at start_time_ns + round(k 1e9 / f), for every
// k with k / f <= duration_s. Ground truth is written at the IMU rate. Each sensor draws from
// its own random stream (seed, sensor), and each image its own (seed, camera, frame), so the
// same scenario and seed give byte-identical output. Work is streamed in time order, memory
// stays flat: the images of a batch of frames (two per processor) are rendered and their PNGs
// written by one worker per processor, in any order (the same bytes: each image has its own
// stream and file), then the batch's rows are written in time order.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "auvdock/io/calibration.h"
#include "auvdock/io/cancellation.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "auvdock/sim/underwater_renderer.h"

namespace auvdock {

struct SimulationSummary {
  int n_imu = 0;
  int n_camera_frames = 0;  // per camera
  int n_depth = 0;
  int n_dvl = 0;
  int n_acoustic = 0;
  int n_heading = 0;
  int n_sbl_ranges = 0;
  int n_faults = 0;
  double max_speed_mps = 0.0;
  // Seconds spent in each visibility stage (stereo only, both, mono only, neither).
  std::array<double, 4> stage_duration_s{};
};

class DockingSimulator {
 public:
  explicit DockingSimulator(const Scenario& scenario);

  const Scenario& scenario() const { return scenario_; }
  const Calibration& calibration() const { return calibration_; }
  const DockingTrajectory& trajectory() const { return trajectory_; }

  // Timestamp of sample k of a sensor at rate_hz.
  int64_t SampleTime(int64_t k, double rate_hz) const;
  // Seconds since the start of the run.
  double Seconds(int64_t t_ns) const;

  // True light counts per camera (geometric visibility, as rendered) and the stage.
  VisibilityRecord VisibilityAt(int64_t t_ns) const;
  // T_D_C of a calibrated camera at time t.
  Pose3 CameraPose(const CameraCalibration& camera, int64_t t_ns) const;

  // Writes the dataset into `dir` (an existing, empty folder). progress(fraction) is called
  // after every camera frame. Throws Cancelled when the token is cancelled. render_workers:
  // threads that render images (0: one per processor); the output does not depend on it.
  SimulationSummary Run(const std::string& dir, const CancellationToken& cancel,
                        const std::function<void(double)>& progress = {},
                        int render_workers = 0) const;

 private:
  Scenario scenario_;
  Calibration calibration_;
  DockingTrajectory trajectory_;
  std::vector<UnderwaterRenderer> renderers_;  // one per camera, in calibration order
};

}  // namespace auvdock
