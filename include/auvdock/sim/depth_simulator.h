// Simulated pressure-depth sensor: depth below the surface of the sensor S, with white noise.
//
//   depth = origin_depth_m + g_hat . p_D_S + n,   p_D_S = T_D_B * p_B_S,   n ~ N(0, sigma_m^2)
// where g_hat = g_D / |g_D| (down). Units: metres.
#pragma once

#include <random>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

class DepthSimulator {
 public:
  DepthSimulator(const DepthCalibration& calibration, const DockModel& dock, bool noise_enabled,
                 std::mt19937_64 rng);
  DepthMeasurement Sample(int64_t t_ns, const KinematicState& s);

 private:
  DepthCalibration calibration_;
  double origin_depth_m_;
  Eigen::Vector3d down_D_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
