// Accuracy of an estimated trajectory against ground truth: absolute pose error (overall and
// per visibility stage) and relative pose error over a fixed time step.
//
// Frames and units: poses are T_D_B (body B in dock frame D); positions in metres, angles in
// radians, time in int64 nanoseconds (options in seconds).
//
// Matching: every estimate pose at time t is compared with the truth interpolated at t --
// linearly in position, slerp in rotation, between the two truth samples around t (the sample
// itself if t falls on one). Estimate poses before the first or after the last truth sample, or
// between two truth samples more than max_truth_gap_s apart, are not evaluated (n_skipped).
//
// Absolute error of a matched pose (after the optional alignment, see below):
//   e_p = p_est - p_true  (in D)
//   pos_rmse_m = sqrt(mean |e_p|^2);  pos_max_abs_m = max |e_p| per axis x, y, z of D;
//   pos_mean_m = mean e_p per axis (the bias).
//   att angle = |Log(R_true^T R_est)| (geodesic);  att_rmse_rad = sqrt(mean angle^2).
//   att_max_abs_rad = max |Wrap(euler_est - euler_true)| per Z-Y-X Euler angle (roll, pitch,
//   yaw; so3.h). The per-axis Euler split is the readable one for a vehicle near level; it
//   degrades near pitch = ±90 deg, where the geodesic angle stays meaningful.
//
// Relative pose error (Sturm et al., IROS 2012; Kümmerle et al. 2009) over delta = rpe_delta_s:
// for each matched estimate pose i, j is the matched pose whose time is closest to t_i + delta
// (pairs with |t_j - t_i - delta| > 0.1 delta are skipped), and
//   E_ij = (T_true_i^-1 T_true_j)^-1 (T_est_i^-1 T_est_j);
//   trans_rmse_m = sqrt(mean |p(E_ij)|^2),  rot_rmse_rad = sqrt(mean angle(E_ij)^2).
// RPE measures drift and is invariant to a rigid change of the estimate's frame. With no pair,
// n_pairs = 0 and the RMSEs are NaN.
//
// Alignment: Alignment::kNone compares the poses as they are (the estimator is meant to
// estimate in the true dock frame D, so a frame offset is an error). Alignment::kSE3 first fits
// T_align (trajectory_alignment.h) to all matched positions and replaces every estimate pose by
// T_align * T_est, which shows the error that remains after removing a rigid frame offset.
//
// Consistency (optional, with the estimate's covariances): for each matched pose with a
// covariance at exactly its timestamp, the normalized estimation error squared
//   NEES = e^T Sigma^-1 e,   e = (p_est - p_true, Log(q_est q_true^-1))   (PoseManifold tangent)
// is chi-square with 6 degrees of freedom when Sigma is honest: mean 6, and 5 % of the poses
// above kNees95 = 12.59. Consecutive poses of one run are correlated, so the mean of one run
// scatters more than independent samples would; the tests average over seeded runs.
//
// Go/no-go audit (optional, with the estimator's decisions): every decision is matched with the
// estimate pose at its timestamp and the truth there; the lateral error is the horizontal
// distance |(p_est - p_true)_xy| in D (D's z is down, so x-y is the dock's plane). A GO whose
// lateral error exceeds options.allowed_lateral_error_m is an unsafe GO -- what the go/no-go
// must never issue. A GO without an estimate pose or truth at its time is counted apart.
//
// Cramér–Rao bound (optional): for each matched pose with a bound P at exactly its timestamp,
// tr P_p and tr P_theta (its position and attitude blocks) are the expected squared errors of
// the best unbiased estimator; ErrorStats reports their RMS beside the estimate's own RMSE over
// the same poses (a ratio near 1: the estimator is as good as the data allow; below 1: the data
// are better than the configured noise models that the bound assumes).
//
// Stages: an estimate pose belongs to the stage of the last visibility record at or before its
// time (kUnknown before the first record or with no records).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"
#include "auvdock/geometry/stamped_pose.h"
#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/measurements.h"
#include "auvdock/io/pose_covariance_csv.h"

namespace auvdock {

enum class Alignment { kNone, kSE3 };

// "none", "se3".
const char* AlignmentName(Alignment alignment);
// Parses "none" or "se3"; returns false on anything else.
bool ParseAlignment(const std::string& text, Alignment* alignment);

struct EvaluationOptions {
  Alignment alignment = Alignment::kNone;
  double rpe_delta_s = 1.0;      // must be positive and finite
  double max_truth_gap_s = 0.1;  // must be positive; +infinity never skips for a gap
  double allowed_lateral_error_m = 0.10;  // for the go/no-go audit (GoNoGoOptions' default)
};

struct ErrorStats {
  int n = 0;  // number of matched poses
  double pos_rmse_m = 0.0;
  double att_rmse_rad = 0.0;
  Eigen::Vector3d pos_max_abs_m = Eigen::Vector3d::Zero();    // x, y, z in D
  Eigen::Vector3d att_max_abs_rad = Eigen::Vector3d::Zero();  // roll, pitch, yaw
  Eigen::Vector3d pos_mean_m = Eigen::Vector3d::Zero();       // signed mean of p_est - p_true
  int nees_n = 0;               // poses with a covariance
  double nees_mean = 0.0;       // NaN when nees_n == 0
  double nees_above_95 = 0.0;   // fraction of NEES > kNees95; NaN when nees_n == 0
  // The NEES of successive poses are not independent (an error lasts as long as what caused it):
  // their integrated autocorrelation time in poses (IntegratedAutocorrelationTime) and
  // nees_n / that, the number of independent values the mean is worth. A 95 % band for
  // nees_mean must use nees_effective_n, not nees_n. NaN when nees_n < 2.
  double nees_correlation_poses = 0.0;
  double nees_effective_n = 0.0;
  // With a Cramér–Rao bound (EstimateReports::bounds): over the poses that have one,
  // sqrt(mean tr P_p) and sqrt(mean tr P_theta), the RMS errors that the best unbiased estimator
  // would have, and pos_rmse_m / att_rmse_rad over the same poses. NaN when bound_n == 0.
  int bound_n = 0;
  double bound_pos_rms_m = 0.0;
  double bound_att_rms_rad = 0.0;
  double pos_rmse_at_bound_m = 0.0;
  double att_rmse_at_bound_rad = 0.0;
};

// tau = 1 + 2 sum_{k>=1} rho_k of a series, the sum stopped at the first lag whose sample
// autocorrelation rho_k is not positive (the initial positive sequence): how many successive
// values carry the information of one independent value (1 for white values, about 5 for
// values that each repeat 5 times); lags up to 1000. NaN for fewer than 2 values or a constant
// series.
double IntegratedAutocorrelationTime(const std::vector<double>& series);

// The 95 % point of the chi-square distribution with 6 degrees of freedom.
inline constexpr double kNees95 = 12.5916;

struct RpeStats {
  int n_pairs = 0;
  double delta_s = 0.0;
  double trans_rmse_m = 0.0;  // NaN when n_pairs == 0
  double rot_rmse_rad = 0.0;  // NaN when n_pairs == 0
};

struct DecisionAudit {
  int n_go = 0;
  int n_no_go = 0;
  int n_go_unsafe = 0;              // GO with lateral error > allowed_lateral_error_m
  int n_go_unmatched = 0;           // GO with no estimate pose or no truth at its time
  double max_lateral_error_at_go_m = 0.0;
  double max_yaw_error_at_go_rad = 0.0;
};

// What the estimator reported besides its poses; both optional.
struct EstimateReports {
  std::vector<StampedPoseCovariance> covariances;
  std::vector<StampedDecision> decisions;
  // The Cramér–Rao bound per pose (`auvdock crlb`, estimator/cramer_rao_bound.h), matched by
  // exact timestamp like the covariances.
  std::vector<StampedPoseCovariance> bounds;
};

struct EvaluationReport {
  ErrorStats overall;
  RpeStats rpe;
  // Only stages with n > 0, in the order of VisibilityStage.
  std::vector<std::pair<VisibilityStage, ErrorStats>> by_stage;
  int n_skipped = 0;  // estimate poses outside the truth span or in a truth gap
  Pose3 alignment;    // T_align; identity with Alignment::kNone
  DecisionAudit decisions;  // all zero without decisions
};

// `truth` must have strictly increasing times, `estimate` too (else InputError); `visibility`
// is expected in time order (it is sorted if not). Throws InputError if the truth is empty
// ("dataset has no ground truth"), if no estimate pose can be matched ("estimate has no pose
// within the ground-truth time span ..."), if the options are invalid, or if SE(3) alignment
// is requested on degenerate (collinear) positions, or if covariances or decisions are given
// together with an alignment (both are about the unaligned estimate).
EvaluationReport EvaluateTrajectory(const std::vector<GroundTruthState>& truth,
                                    const Trajectory& estimate,
                                    const std::vector<VisibilityRecord>& visibility,
                                    const EvaluationOptions& options,
                                    const EstimateReports& reports = {});

}  // namespace auvdock
