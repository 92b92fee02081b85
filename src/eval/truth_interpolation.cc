#include "auvdock/eval/truth_interpolation.h"

#include <algorithm>

namespace auvdock {

TruthLookup InterpolateTruth(const std::vector<GroundTruthState>& truth, int64_t t_ns,
                             double max_gap_s, GroundTruthState* state) {
  const auto after =
      std::lower_bound(truth.begin(), truth.end(), t_ns,
                       [](const GroundTruthState& s, int64_t t) { return s.t_ns < t; });
  if (after == truth.end()) return TruthLookup::kOutsideSpan;
  if (after->t_ns == t_ns) {
    *state = *after;
    return TruthLookup::kFound;
  }
  if (after == truth.begin()) return TruthLookup::kOutsideSpan;
  const GroundTruthState& a = *(after - 1);
  const GroundTruthState& b = *after;
  const int64_t gap_ns = b.t_ns - a.t_ns;
  // 0.1 * 1e9 rounds to exactly 1e8 while 1e8 * 1e-9 may exceed 0.1.
  if (static_cast<double>(gap_ns) > max_gap_s * 1e9) return TruthLookup::kInGap;
  const double alpha = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(gap_ns);
  state->t_ns = t_ns;
  state->T_D_B = Interpolate(a.T_D_B, b.T_D_B, alpha);
  state->v_D = (1.0 - alpha) * a.v_D + alpha * b.v_D;
  state->gyro_bias = (1.0 - alpha) * a.gyro_bias + alpha * b.gyro_bias;
  state->accel_bias = (1.0 - alpha) * a.accel_bias + alpha * b.accel_bias;
  return TruthLookup::kFound;
}

}  // namespace auvdock
