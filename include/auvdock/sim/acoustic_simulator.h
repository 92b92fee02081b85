// Simulated acoustic (USBL/SBL) position fix of the vehicle's transducer in D (seed 001).
//
//   p_D = T_D_B * p_B_S + n,  n ~ N(0, sigma^2 I),  sigma = max(sigma_min, fraction * range)
// with range the slant range from the dock beacon. The fix reports its nominal sigma. With
// probability outlier_probability an outlier of random direction and magnitude uniform in
// [0.5, 1] * outlier_m is added (multipath), and reported as a FaultRecord. Each fix arrives
// late, latency ~ U[latency_min_s, latency_max_s] after its measurement (it is computed on the
// dock or ashore and sent back acoustically; AcousticFix::latency_ns), drawn whether or not
// noise is enabled. Units: metres, seconds.
#pragma once

#include <optional>
#include <random>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

struct AcousticFaultConfig {
  double outlier_probability = 0.05;
  double outlier_m = 2.0;
  double latency_min_s = 0.2;
  double latency_max_s = 1.0;
};

class AcousticSimulator {
 public:
  AcousticSimulator(const AcousticCalibration& calibration, const DockModel& dock,
                    const AcousticFaultConfig& faults, bool noise_enabled, std::mt19937_64 rng);
  AcousticFix Sample(int64_t t_ns, const KinematicState& s, std::optional<FaultRecord>* fault);

 private:
  AcousticCalibration calibration_;
  Eigen::Vector3d p_D_beacon_;
  AcousticFaultConfig faults_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
