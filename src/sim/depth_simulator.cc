#include "auvdock/sim/depth_simulator.h"

#include <sstream>

#include "auvdock/sim/random_stream.h"

namespace auvdock {

DepthSimulator::DepthSimulator(const DepthCalibration& calibration,
                               const DepthFaultConfig& faults, const DockModel& dock,
                               bool noise_enabled, std::mt19937_64 rng)
    : calibration_(calibration), faults_(faults), origin_depth_m_(dock.origin_depth_m),
      down_D_(dock.gravity_D.normalized()), noise_enabled_(noise_enabled), rng_(std::move(rng)) {}

DepthMeasurement DepthSimulator::Sample(int64_t t_ns, const KinematicState& s,
                                        std::optional<FaultRecord>* fault) {
  if (!t_first_ns_) {
    t_first_ns_ = t_ns;
    if (fault != nullptr && (faults_.bias_m != 0.0 || faults_.bias_rate_mps != 0.0)) {
      std::ostringstream detail;
      detail << "bias_m=" << faults_.bias_m << ";rate_mps=" << faults_.bias_rate_mps;
      *fault = FaultRecord{t_ns, calibration_.name, "bias", detail.str()};
    }
  }
  const Eigen::Vector3d p_D_S = s.T_D_B * calibration_.T_B_S.p;
  DepthMeasurement m;
  m.t_ns = t_ns;
  const double since_first_s = 1e-9 * static_cast<double>(t_ns - *t_first_ns_);
  m.depth_m = origin_depth_m_ + down_D_.dot(p_D_S) + faults_.bias_m +
              faults_.bias_rate_mps * since_first_s;
  if (noise_enabled_) m.depth_m += calibration_.sigma_m * StandardNormal(rng_);
  return m;
}

}  // namespace auvdock
