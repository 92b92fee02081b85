#include "auvdock/sim/acoustic_simulator.h"

#include <algorithm>
#include <cmath>

#include "auvdock/io/csv.h"
#include "auvdock/sim/random_stream.h"

namespace auvdock {

AcousticSimulator::AcousticSimulator(const AcousticCalibration& calibration,
                                     const DockModel& dock, const AcousticFaultConfig& faults,
                                     bool noise_enabled, std::mt19937_64 rng)
    : calibration_(calibration), p_D_beacon_(dock.p_D_beacon), faults_(faults),
      noise_enabled_(noise_enabled), rng_(std::move(rng)) {}

AcousticFix AcousticSimulator::Sample(int64_t t_ns, const KinematicState& s,
                                      std::optional<FaultRecord>* fault) {
  fault->reset();
  const Eigen::Vector3d p_D_S = s.T_D_B * calibration_.T_B_S.p;
  const double range = (p_D_S - p_D_beacon_).norm();
  AcousticFix fix;
  fix.t_ns = t_ns;
  fix.p_D = p_D_S;
  fix.sigma_m = std::max(calibration_.sigma_min_m, calibration_.sigma_range_fraction * range);
  const double latency_s =
      faults_.latency_min_s + (faults_.latency_max_s - faults_.latency_min_s) * Uniform01(rng_);
  fix.latency_ns = static_cast<int64_t>(std::llround(latency_s * 1e9));
  if (!noise_enabled_) return fix;
  fix.p_D += fix.sigma_m * StandardNormal3(rng_);
  if (Uniform01(rng_) < faults_.outlier_probability) {
    const Eigen::Vector3d error =
        faults_.outlier_m * (0.5 + 0.5 * Uniform01(rng_)) * StandardNormal3(rng_).normalized();
    fix.p_D += error;
    *fault = FaultRecord{t_ns, calibration_.name, "outlier",
                         "dp=" + FormatDouble(error.x()) + ";" + FormatDouble(error.y()) + ";" +
                             FormatDouble(error.z())};
  }
  return fix;
}

}  // namespace auvdock
