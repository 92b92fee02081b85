#include "auvdock/estimator/cramer_rao_bound.h"

#include <algorithm>
#include <stdexcept>

#include "factors/pose_manifold.h"

namespace auvdock {
namespace {

void WriteState(const GroundTruthState& s, StateRecord* r) {
  PoseToBlock(s.T_D_B, r->pose);
  Eigen::Map<Eigen::Vector3d>(r->velocity) = s.v_D;
  Eigen::Map<Eigen::Vector3d>(r->bias) = s.gyro_bias;
  Eigen::Map<Eigen::Vector3d>(r->bias + 3) = s.accel_bias;
}

}  // namespace

std::optional<StateRecord> TrueStateAt(const std::vector<GroundTruthState>& truth, int64_t t_ns,
                                       double max_gap_s) {
  const auto after =
      std::lower_bound(truth.begin(), truth.end(), t_ns,
                       [](const GroundTruthState& s, int64_t t) { return s.t_ns < t; });
  if (after == truth.end()) return std::nullopt;
  StateRecord r;
  r.t_ns = t_ns;
  if (after->t_ns == t_ns) {
    WriteState(*after, &r);
    return r;
  }
  if (after == truth.begin()) return std::nullopt;
  const GroundTruthState& a = *(after - 1);
  const GroundTruthState& b = *after;
  const int64_t gap_ns = b.t_ns - a.t_ns;
  if (static_cast<double>(gap_ns) > max_gap_s * 1e9) return std::nullopt;
  const double alpha = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(gap_ns);
  GroundTruthState s;
  s.t_ns = t_ns;
  s.T_D_B = Interpolate(a.T_D_B, b.T_D_B, alpha);
  s.v_D = (1.0 - alpha) * a.v_D + alpha * b.v_D;
  s.gyro_bias = (1.0 - alpha) * a.gyro_bias + alpha * b.gyro_bias;
  s.accel_bias = (1.0 - alpha) * a.accel_bias + alpha * b.accel_bias;
  WriteState(s, &r);
  return r;
}

CramerRaoBound ComputeCramerRaoBound(const Calibration& calibration, const DockModel& dock,
                                     const std::vector<VisionFrame>& frames,
                                     const std::vector<ImuSample>& imu,
                                     const std::vector<GroundTruthState>& truth,
                                     const EstimatorOptions& estimator_options,
                                     const NavigationSamples& sensors, double max_truth_gap_s) {
  if (truth.empty()) throw std::invalid_argument("ComputeCramerRaoBound: no ground truth");
  CramerRaoBound bound;
  bound.frames = static_cast<int>(frames.size());
  std::vector<StateRecord> truth_states;
  for (const VisionFrame& frame : frames) {
    if (const std::optional<StateRecord> s = TrueStateAt(truth, frame.t_ns, max_truth_gap_s)) {
      truth_states.push_back(*s);
    } else {
      ++bound.frames_without_truth;
    }
  }
  BatchSmootherOptions options;
  options.information_at_warm_start = true;
  const BatchResult result = SmoothBatch(calibration, dock, frames, imu, truth_states,
                                         estimator_options, options, sensors);
  bound.stats = result.stats;
  bound.covariance_failures = result.stats.covariance_failures;
  for (const EstimatorOutput& out : result.outputs) {
    if (out.covariance_ok) bound.poses.push_back({out.t_ns, out.covariance});
  }
  return bound;
}

}  // namespace auvdock
