#include "auvdock/eval/trajectory_evaluation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include "auvdock/eval/trajectory_alignment.h"
#include "auvdock/eval/truth_interpolation.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/io/input_error.h"

namespace auvdock {
namespace {

constexpr int kNumStages = static_cast<int>(VisibilityStage::kUnknown) + 1;
// RPE pairs whose time step misses delta by more than this fraction of delta are not used.
constexpr double kRpeTimeTolerance = 0.1;
// IntegratedAutocorrelationTime sums lags up to this (a slowly trending series would otherwise
// cost n^2 on a long log).
constexpr int kMaxAutocorrelationLag = 1000;

struct MatchedPose {
  int64_t t_ns = 0;
  Pose3 T_est;
  Pose3 T_true;
  VisibilityStage stage = VisibilityStage::kUnknown;
  const Eigen::Matrix<double, 6, 6>* covariance = nullptr;  // when the estimate has one here
  const Eigen::Matrix<double, 6, 6>* bound = nullptr;       // when a bound is given here
};

// e^T Sigma^-1 e with e = Minus(T_est, T_true) in the PoseManifold tangent space.
double PoseNees(const Pose3& T_est, const Pose3& T_true, const Eigen::Matrix<double, 6, 6>& sigma) {
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = T_est.p - T_true.p;
  e.tail<3>() = LogQuaternion(T_est.q * T_true.q.conjugate());
  return e.dot(sigma.ldlt().solve(e));
}

// Sums for the absolute-error statistics of one group of poses.
class ErrorAccumulator {
 public:
  void Add(const Pose3& T_est, const Pose3& T_true) {
    const Eigen::Vector3d e = T_est.p - T_true.p;
    ++n_;
    sum_sq_pos_ += e.squaredNorm();
    sum_pos_ += e;
    max_abs_pos_ = max_abs_pos_.cwiseMax(e.cwiseAbs());

    const double angle = RotationAngleBetween(T_true.q, T_est.q);
    sum_sq_att_ += angle * angle;
    const Eigen::Vector3d rpy_est = RollPitchYawFromQuaternion(T_est.q);
    const Eigen::Vector3d rpy_true = RollPitchYawFromQuaternion(T_true.q);
    for (int k = 0; k < 3; ++k) {
      max_abs_att_(k) = std::max(max_abs_att_(k), std::abs(WrapAngle(rpy_est(k) - rpy_true(k))));
    }
  }

  void AddNees(double nees) {
    ++nees_n_;
    nees_sum_ += nees;
    if (nees > kNees95) ++nees_above_;
    nees_series_.push_back(nees);
  }

  // The bound at a pose, with that pose's own errors.
  void AddBound(const Pose3& T_est, const Pose3& T_true, const Eigen::Matrix<double, 6, 6>& bound) {
    ++bound_n_;
    bound_pos_sum_ += bound.topLeftCorner<3, 3>().trace();
    bound_att_sum_ += bound.bottomRightCorner<3, 3>().trace();
    at_bound_pos_sq_ += (T_est.p - T_true.p).squaredNorm();
    const double angle = RotationAngleBetween(T_true.q, T_est.q);
    at_bound_att_sq_ += angle * angle;
  }

  int n() const { return n_; }

  ErrorStats Stats() const {
    ErrorStats stats;
    stats.n = n_;
    if (n_ == 0) return stats;
    stats.pos_rmse_m = std::sqrt(sum_sq_pos_ / n_);
    stats.att_rmse_rad = std::sqrt(sum_sq_att_ / n_);
    stats.pos_max_abs_m = max_abs_pos_;
    stats.att_max_abs_rad = max_abs_att_;
    stats.pos_mean_m = sum_pos_ / n_;
    stats.nees_n = nees_n_;
    stats.nees_mean = nees_n_ > 0 ? nees_sum_ / nees_n_ : std::nan("");
    stats.nees_above_95 =
        nees_n_ > 0 ? static_cast<double>(nees_above_) / nees_n_ : std::nan("");
    stats.nees_correlation_poses = IntegratedAutocorrelationTime(nees_series_);
    stats.nees_effective_n = nees_n_ / stats.nees_correlation_poses;
    stats.bound_n = bound_n_;
    const auto rms = [&](double sum) {
      return bound_n_ > 0 ? std::sqrt(sum / bound_n_) : std::nan("");
    };
    stats.bound_pos_rms_m = rms(bound_pos_sum_);
    stats.bound_att_rms_rad = rms(bound_att_sum_);
    stats.pos_rmse_at_bound_m = rms(at_bound_pos_sq_);
    stats.att_rmse_at_bound_rad = rms(at_bound_att_sq_);
    return stats;
  }

 private:
  int n_ = 0;
  double sum_sq_pos_ = 0.0;
  double sum_sq_att_ = 0.0;
  Eigen::Vector3d sum_pos_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_abs_pos_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_abs_att_ = Eigen::Vector3d::Zero();
  int nees_n_ = 0;
  int nees_above_ = 0;
  double nees_sum_ = 0.0;
  std::vector<double> nees_series_;  // in time order
  int bound_n_ = 0;
  double bound_pos_sum_ = 0.0, bound_att_sum_ = 0.0;
  double at_bound_pos_sq_ = 0.0, at_bound_att_sq_ = 0.0;
};

std::string Seconds(int64_t t_ns) {
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "%.3f", static_cast<double>(t_ns) * 1e-9);
  return buffer;
}

std::string Number(double value) {
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

void ValidateInputs(const std::vector<GroundTruthState>& truth, const Trajectory& estimate,
                    const EvaluationOptions& options) {
  if (!(options.rpe_delta_s > 0.0) || !(options.rpe_delta_s < 1e9)) {
    throw InputError("RPE delta must be positive and finite (got " + Number(options.rpe_delta_s) +
                     " s)");
  }
  if (!(options.max_truth_gap_s > 0.0)) {
    throw InputError("maximum ground-truth gap must be positive (got " +
                     Number(options.max_truth_gap_s) + " s)");
  }
  if (truth.empty()) throw InputError("dataset has no ground truth");
  for (size_t i = 1; i < truth.size(); ++i) {
    if (truth[i].t_ns <= truth[i - 1].t_ns) {
      throw InputError("ground truth times are not strictly increasing at sample " +
                       std::to_string(i) + " (t = " + Seconds(truth[i].t_ns) + " s)");
    }
  }
  for (size_t i = 1; i < estimate.size(); ++i) {
    if (estimate[i].t_ns <= estimate[i - 1].t_ns) {
      throw InputError("estimate times are not strictly increasing at pose " + std::to_string(i) +
                       " (t = " + Seconds(estimate[i].t_ns) + " s)");
    }
  }
}

// `visibility` sorted by time. The stage of the last record at or before t_ns.
VisibilityStage StageAt(const std::vector<VisibilityRecord>& visibility, int64_t t_ns) {
  const auto after =
      std::upper_bound(visibility.begin(), visibility.end(), t_ns,
                       [](int64_t t, const VisibilityRecord& r) { return t < r.t_ns; });
  if (after == visibility.begin()) return VisibilityStage::kUnknown;
  return (after - 1)->stage;
}

RpeStats ComputeRpe(const std::vector<MatchedPose>& matched, double delta_s) {
  RpeStats rpe;
  rpe.delta_s = delta_s;
  const int64_t delta_ns = std::llround(delta_s * 1e9);
  const double tolerance_ns = kRpeTimeTolerance * static_cast<double>(delta_ns);
  double sum_sq_trans = 0.0;
  double sum_sq_rot = 0.0;
  for (size_t i = 0; i < matched.size(); ++i) {
    const int64_t target_ns = matched[i].t_ns + delta_ns;
    // The closest of the poses just before and just after the target time (both after i).
    const size_t after = static_cast<size_t>(
        std::lower_bound(matched.begin() + i + 1, matched.end(), target_ns,
                         [](const MatchedPose& m, int64_t t) { return m.t_ns < t; }) -
        matched.begin());
    size_t j = matched.size();
    double best_miss_ns = std::numeric_limits<double>::infinity();
    for (size_t candidate : {after - 1, after}) {
      if (candidate <= i || candidate >= matched.size()) continue;
      const double miss_ns = std::abs(static_cast<double>(matched[candidate].t_ns - target_ns));
      if (miss_ns < best_miss_ns) {
        j = candidate;
        best_miss_ns = miss_ns;
      }
    }
    if (j == matched.size() || best_miss_ns > tolerance_ns) continue;

    const Pose3 delta_true = matched[i].T_true.Inverse() * matched[j].T_true;
    const Pose3 delta_est = matched[i].T_est.Inverse() * matched[j].T_est;
    const Pose3 E = delta_true.Inverse() * delta_est;
    const double angle = LogQuaternion(E.q).norm();
    sum_sq_trans += E.p.squaredNorm();
    sum_sq_rot += angle * angle;
    ++rpe.n_pairs;
  }
  if (rpe.n_pairs == 0) {
    rpe.trans_rmse_m = std::numeric_limits<double>::quiet_NaN();
    rpe.rot_rmse_rad = std::numeric_limits<double>::quiet_NaN();
  } else {
    rpe.trans_rmse_m = std::sqrt(sum_sq_trans / rpe.n_pairs);
    rpe.rot_rmse_rad = std::sqrt(sum_sq_rot / rpe.n_pairs);
  }
  return rpe;
}

DecisionAudit AuditDecisions(const std::vector<MatchedPose>& matched,
                            const std::vector<StampedDecision>& decisions, double allowed_m) {
  std::unordered_map<int64_t, const MatchedPose*> pose_at;
  for (const MatchedPose& m : matched) pose_at[m.t_ns] = &m;
  DecisionAudit audit;
  for (const StampedDecision& d : decisions) {
    if (!d.go) {
      ++audit.n_no_go;
      continue;
    }
    ++audit.n_go;
    const auto it = pose_at.find(d.t_ns);
    if (it == pose_at.end()) {
      ++audit.n_go_unmatched;
      continue;
    }
    const MatchedPose& m = *it->second;
    const double lateral = (m.T_est.p - m.T_true.p).head<2>().norm();
    const double yaw = std::abs(WrapAngle(RollPitchYawFromQuaternion(m.T_est.q).z() -
                                          RollPitchYawFromQuaternion(m.T_true.q).z()));
    audit.max_lateral_error_at_go_m = std::max(audit.max_lateral_error_at_go_m, lateral);
    audit.max_yaw_error_at_go_rad = std::max(audit.max_yaw_error_at_go_rad, yaw);
    if (lateral > allowed_m) ++audit.n_go_unsafe;
  }
  return audit;
}

}  // namespace

double IntegratedAutocorrelationTime(const std::vector<double>& series) {
  const int n = static_cast<int>(series.size());
  if (n < 2) return std::nan("");
  double mean = 0.0;
  for (double x : series) mean += x;
  mean /= n;
  double variance = 0.0;
  for (double x : series) variance += (x - mean) * (x - mean);
  if (!(variance > 0.0)) return std::nan("");
  double tau = 1.0;
  for (int lag = 1; lag < std::min(n, kMaxAutocorrelationLag + 1); ++lag) {
    double covariance = 0.0;
    for (int i = 0; i + lag < n; ++i) covariance += (series[i] - mean) * (series[i + lag] - mean);
    const double rho = covariance / variance;
    if (!(rho > 0.0)) break;
    tau += 2.0 * rho;
  }
  return tau;
}

const char* AlignmentName(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSE3:
      return "se3";
  }
  return "none";
}

bool ParseAlignment(const std::string& text, Alignment* alignment) {
  for (Alignment a : {Alignment::kNone, Alignment::kSE3}) {
    if (text == AlignmentName(a)) {
      *alignment = a;
      return true;
    }
  }
  return false;
}

EvaluationReport EvaluateTrajectory(const std::vector<GroundTruthState>& truth,
                                    const Trajectory& estimate,
                                    const std::vector<VisibilityRecord>& visibility,
                                    const EvaluationOptions& options,
                                    const EstimateReports& reports) {
  ValidateInputs(truth, estimate, options);
  if ((!reports.covariances.empty() || !reports.decisions.empty() || !reports.bounds.empty()) &&
      options.alignment != Alignment::kNone) {
    throw InputError("covariances, decisions and bounds are about the unaligned estimate: "
                     "evaluate them without alignment");
  }
  if (!(options.allowed_lateral_error_m > 0.0)) {
    throw InputError("allowed lateral error must be positive (got " +
                     Number(options.allowed_lateral_error_m) + " m)");
  }
  std::unordered_map<int64_t, const Eigen::Matrix<double, 6, 6>*> covariance_at;
  for (const StampedPoseCovariance& c : reports.covariances) covariance_at[c.t_ns] = &c.covariance;
  std::unordered_map<int64_t, const Eigen::Matrix<double, 6, 6>*> bound_at;
  for (const StampedPoseCovariance& b : reports.bounds) bound_at[b.t_ns] = &b.covariance;

  std::vector<VisibilityRecord> sorted_visibility;
  const std::vector<VisibilityRecord>* stages = &visibility;
  const auto by_time = [](const VisibilityRecord& a, const VisibilityRecord& b) {
    return a.t_ns < b.t_ns;
  };
  if (!std::is_sorted(visibility.begin(), visibility.end(), by_time)) {
    sorted_visibility = visibility;
    std::stable_sort(sorted_visibility.begin(), sorted_visibility.end(), by_time);
    stages = &sorted_visibility;
  }

  EvaluationReport report;
  std::vector<MatchedPose> matched;
  matched.reserve(estimate.size());
  int n_in_gap = 0;
  for (const StampedPose& pose : estimate) {
    MatchedPose m;
    GroundTruthState true_state;
    const TruthLookup lookup =
        InterpolateTruth(truth, pose.t_ns, options.max_truth_gap_s, &true_state);
    if (lookup != TruthLookup::kFound) {
      ++report.n_skipped;
      if (lookup == TruthLookup::kInGap) ++n_in_gap;
      continue;
    }
    m.t_ns = pose.t_ns;
    m.T_true = true_state.T_D_B;
    m.T_est = pose.T_D_B;
    m.stage = StageAt(*stages, pose.t_ns);
    const auto covariance = covariance_at.find(pose.t_ns);
    if (covariance != covariance_at.end()) m.covariance = covariance->second;
    const auto bound = bound_at.find(pose.t_ns);
    if (bound != bound_at.end()) m.bound = bound->second;
    matched.push_back(m);
  }

  if (matched.empty()) {
    std::string message = "estimate has no pose within the ground-truth time span [" +
                          Seconds(truth.front().t_ns) + ", " + Seconds(truth.back().t_ns) + "] s";
    if (estimate.empty()) {
      message += " (the estimate is empty)";
    } else if (n_in_gap > 0) {
      message += " (" + std::to_string(n_in_gap) + " poses fall in ground-truth gaps longer than " +
                 Number(options.max_truth_gap_s) + " s)";
    } else {
      message += " (the estimate spans [" + Seconds(estimate.front().t_ns) + ", " +
                 Seconds(estimate.back().t_ns) + "] s)";
    }
    throw InputError(message);
  }

  if (options.alignment == Alignment::kSE3) {
    std::vector<Eigen::Vector3d> p_est, p_true;
    p_est.reserve(matched.size());
    p_true.reserve(matched.size());
    for (const MatchedPose& m : matched) {
      p_est.push_back(m.T_est.p);
      p_true.push_back(m.T_true.p);
    }
    report.alignment = AlignPositionsSE3(p_est, p_true);
    for (MatchedPose& m : matched) m.T_est = report.alignment * m.T_est;
  }

  ErrorAccumulator overall;
  std::array<ErrorAccumulator, kNumStages> per_stage;
  for (const MatchedPose& m : matched) {
    overall.Add(m.T_est, m.T_true);
    per_stage[static_cast<int>(m.stage)].Add(m.T_est, m.T_true);
    if (m.covariance != nullptr) {
      const double nees = PoseNees(m.T_est, m.T_true, *m.covariance);
      overall.AddNees(nees);
      per_stage[static_cast<int>(m.stage)].AddNees(nees);
    }
    if (m.bound != nullptr) {
      overall.AddBound(m.T_est, m.T_true, *m.bound);
      per_stage[static_cast<int>(m.stage)].AddBound(m.T_est, m.T_true, *m.bound);
    }
  }
  report.overall = overall.Stats();
  for (int s = 0; s < kNumStages; ++s) {
    if (per_stage[s].n() > 0) {
      report.by_stage.emplace_back(static_cast<VisibilityStage>(s), per_stage[s].Stats());
    }
  }
  report.rpe = ComputeRpe(matched, options.rpe_delta_s);
  report.decisions = AuditDecisions(matched, reports.decisions, options.allowed_lateral_error_m);
  return report;
}

}  // namespace auvdock
