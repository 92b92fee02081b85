#include "auvdock/sim/depth_simulator.h"

#include "auvdock/sim/random_stream.h"

namespace auvdock {

DepthSimulator::DepthSimulator(const DepthCalibration& calibration, const DockModel& dock,
                               bool noise_enabled, std::mt19937_64 rng)
    : calibration_(calibration), origin_depth_m_(dock.origin_depth_m),
      down_D_(dock.gravity_D.normalized()), noise_enabled_(noise_enabled), rng_(std::move(rng)) {}

DepthMeasurement DepthSimulator::Sample(int64_t t_ns, const KinematicState& s) {
  const Eigen::Vector3d p_D_S = s.T_D_B * calibration_.T_B_S.p;
  DepthMeasurement m;
  m.t_ns = t_ns;
  m.depth_m = origin_depth_m_ + down_D_.dot(p_D_S);
  if (noise_enabled_) m.depth_m += calibration_.sigma_m * StandardNormal(rng_);
  return m;
}

}  // namespace auvdock
