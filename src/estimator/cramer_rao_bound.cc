#include "auvdock/estimator/cramer_rao_bound.h"

#include <stdexcept>

#include "auvdock/eval/truth_interpolation.h"
#include "factors/pose_manifold.h"

namespace auvdock {
std::optional<StateRecord> TrueStateAt(const std::vector<GroundTruthState>& truth, int64_t t_ns,
                                       double max_gap_s) {
  GroundTruthState s;
  if (InterpolateTruth(truth, t_ns, max_gap_s, &s) != TruthLookup::kFound) return std::nullopt;
  StateRecord r;
  r.t_ns = t_ns;
  PoseToBlock(s.T_D_B, r.pose);
  Eigen::Map<Eigen::Vector3d>(r.velocity) = s.v_D;
  Eigen::Map<Eigen::Vector3d>(r.bias) = s.gyro_bias;
  Eigen::Map<Eigen::Vector3d>(r.bias + 3) = s.accel_bias;
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
