// Simulated short-baseline (SBL) ranges (seed 001): each transducer T_k of the hull's array
// times the reply of the dock's beacon F (dock.yaml beacon_p_D) on its own,
//   rho_k = |T_D_B p_B_Tk - p_D_F| + n_k,  n_k ~ N(0, sigma_k^2),
//   sigma_k = max(sigma_min_m, sigma_range_fraction x |T_D_B p_B_Tk - p_D_F|),
// each range reporting its nominal sigma_k. What real SBL arrays do beside that noise:
//   - a blind zone: nearer than min_range_m a transducer gets no usable reply (seed 001: the
//     acoustic positioning goes blind close to the dock, where vision takes over): no range;
//   - a missed reply with probability dropout_probability: no range;
//   - multipath with probability outlier_probability: the reply came the long way round, the
//     range is longer by U[0.5, 1] x outlier_m; reported as a FaultRecord (kind "outlier").
// A ping is measured on the vehicle: its ranges carry the ping's time and no latency.
// Units: metres, seconds.
#pragma once

#include <random>
#include <vector>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

struct SblFaultConfig {
  double min_range_m = 1.0;
  double dropout_probability = 0.05;
  double outlier_probability = 0.02;
  double outlier_m = 1.0;
};

class SblSimulator {
 public:
  SblSimulator(const SblCalibration& calibration, const DockModel& dock,
               const SblFaultConfig& faults, bool noise_enabled, std::mt19937_64 rng);
  // The ranges of one ping at t_ns (transducers in index order, those without a reply left
  // out); each injected outlier is appended to *faults.
  std::vector<SblRange> Ping(int64_t t_ns, const KinematicState& s,
                             std::vector<FaultRecord>* faults);

 private:
  SblCalibration calibration_;
  Eigen::Vector3d p_D_beacon_;
  SblFaultConfig faults_;
  bool noise_enabled_;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
