// Simulated pressure-depth sensor: depth below the surface of the sensor S, with white noise and
// an offset from the dock survey's depth (the tide since the survey, the air pressure, a sensor
// bias: scenario keys depth.bias_m and depth.bias_rate_mps):
//
//   depth = origin_depth_m + g_hat . p_D_S + b(t) + n,   p_D_S = T_D_B * p_B_S,
//   b(t) = bias_m + bias_rate_mps (t - t_first),          n ~ N(0, sigma_m^2)
// where g_hat = g_D / |g_D| (down) and t_first the first sample's time. A non-zero offset is
// listed in groundtruth/faults.csv at the first sample ("bias", its value and rate).
// Units: metres, seconds.
#pragma once

#include <optional>
#include <random>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

struct DepthFaultConfig {
  double bias_m = 0.0;         // the offset at the first sample
  double bias_rate_mps = 0.0;  // its drift (a tide of 1 m in 6 h: 4.6e-5 m/s)
};

class DepthSimulator {
 public:
  DepthSimulator(const DepthCalibration& calibration, const DepthFaultConfig& faults,
                 const DockModel& dock, bool noise_enabled, std::mt19937_64 rng);
  // *fault: the offset's record at the first sample when it is not zero (else untouched).
  DepthMeasurement Sample(int64_t t_ns, const KinematicState& s,
                          std::optional<FaultRecord>* fault = nullptr);

 private:
  DepthCalibration calibration_;
  DepthFaultConfig faults_;
  std::optional<int64_t> t_first_ns_;
  double origin_depth_m_;
  Eigen::Vector3d down_D_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
