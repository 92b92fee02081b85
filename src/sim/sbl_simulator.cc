#include "auvdock/sim/sbl_simulator.h"

#include <algorithm>
#include <utility>

#include "auvdock/io/csv.h"
#include "auvdock/sim/random_stream.h"

namespace auvdock {

SblSimulator::SblSimulator(const SblCalibration& calibration, const DockModel& dock,
                           const SblFaultConfig& faults, bool noise_enabled, std::mt19937_64 rng)
    : calibration_(calibration), p_D_beacon_(dock.p_D_beacon), faults_(faults),
      noise_enabled_(noise_enabled), rng_(std::move(rng)) {}

std::vector<SblRange> SblSimulator::Ping(int64_t t_ns, const KinematicState& s,
                                         std::vector<FaultRecord>* faults) {
  std::vector<SblRange> ranges;
  for (size_t k = 0; k < calibration_.p_B_transducers.size(); ++k) {
    const double range = (s.T_D_B * calibration_.p_B_transducers[k] - p_D_beacon_).norm();
    // Every draw is made whatever the outcome, so that one transducer's blind zone does not
    // change the others' noise.
    const double noise = StandardNormal(rng_);
    const bool dropped = Uniform01(rng_) < faults_.dropout_probability;
    const bool multipath = Uniform01(rng_) < faults_.outlier_probability;
    const double detour = faults_.outlier_m * (0.5 + 0.5 * Uniform01(rng_));
    if (range < faults_.min_range_m) continue;
    SblRange m;
    m.t_ns = t_ns;
    m.transducer = static_cast<int>(k);
    m.sigma_m = std::max(calibration_.sigma_min_m, calibration_.sigma_range_fraction * range);
    m.range_m = range;
    if (noise_enabled_) {
      if (dropped) continue;
      m.range_m = std::max(0.0, range + m.sigma_m * noise);
      if (multipath) {
        m.range_m += detour;
        faults->push_back({t_ns, calibration_.name, "outlier",
                           "transducer=" + std::to_string(k) + ";dr=" + FormatDouble(detour)});
      }
    }
    ranges.push_back(m);
  }
  return ranges;
}

}  // namespace auvdock
