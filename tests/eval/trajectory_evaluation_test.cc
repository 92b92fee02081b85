#include "auvdock/eval/trajectory_evaluation.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/input_error.h"
#include "tests/testing/trajectory_factory.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kT0 = 1'000'000'000'000;  // 1000 s
constexpr int64_t kSecond = 1'000'000'000;
constexpr int64_t kDt = 10'000'000;  // 100 Hz
constexpr int kNumSamples = 2001;    // 20 s

std::vector<GroundTruthState> Truth() {
  return test::MakeSmoothApproachTruth(kT0, kDt, kNumSamples);
}

void ExpectAllZero(const ErrorStats& s, double tol) {
  EXPECT_LE(s.pos_rmse_m, tol);
  EXPECT_LE(s.att_rmse_rad, tol);
  EXPECT_LE(s.pos_max_abs_m.maxCoeff(), tol);
  EXPECT_LE(s.att_max_abs_rad.maxCoeff(), tol);
  EXPECT_LE(s.pos_mean_m.cwiseAbs().maxCoeff(), tol);
}

VisibilityRecord Record(int64_t t_ns, VisibilityStage stage) {
  VisibilityRecord r;
  r.t_ns = t_ns;
  r.stage = stage;
  return r;
}

std::string EvaluationError(const std::vector<GroundTruthState>& truth, const Trajectory& estimate,
                            const EvaluationOptions& options = {}) {
  try {
    EvaluateTrajectory(truth, estimate, {}, options);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(EvaluateTrajectoryTest, TruthAgainstItselfHasNoError) {
  const std::vector<GroundTruthState> truth = Truth();
  const EvaluationReport report =
      EvaluateTrajectory(truth, test::TrajectoryFromTruth(truth), {}, EvaluationOptions());
  EXPECT_EQ(report.overall.n, kNumSamples);
  EXPECT_EQ(report.n_skipped, 0);
  ExpectAllZero(report.overall, 1e-12);
  // Every pose up to 0.9 s before the end has a partner: 1 s later, or the last pose when that
  // is at most 10 % short of 1 s.
  EXPECT_EQ(report.rpe.n_pairs, kNumSamples - 90);
  EXPECT_EQ(report.rpe.delta_s, 1.0);
  EXPECT_LE(report.rpe.trans_rmse_m, 1e-12);
  EXPECT_LE(report.rpe.rot_rmse_rad, 1e-12);
  EXPECT_TRUE(report.alignment.Matrix().isIdentity(0.0));
  // No visibility records: everything is in the unknown stage.
  ASSERT_EQ(report.by_stage.size(), 1u);
  EXPECT_EQ(report.by_stage[0].first, VisibilityStage::kUnknown);
  EXPECT_EQ(report.by_stage[0].second.n, kNumSamples);
}

TEST(EvaluateTrajectoryTest, ConstantPositionOffset) {
  const std::vector<GroundTruthState> truth = Truth();
  const Eigen::Vector3d offset(0.1, -0.2, 0.05);
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  for (StampedPose& pose : estimate) pose.T_D_B.p += offset;
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(report.overall.n, kNumSamples);
  EXPECT_LE((report.overall.pos_mean_m - offset).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LE((report.overall.pos_max_abs_m - offset.cwiseAbs()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(report.overall.pos_rmse_m, offset.norm(), 1e-12);
  EXPECT_LE(report.overall.att_rmse_rad, 1e-12);
  EXPECT_LE(report.overall.att_max_abs_rad.maxCoeff(), 1e-12);
  // A constant offset is no drift.
  EXPECT_LE(report.rpe.trans_rmse_m, 1e-12);
  EXPECT_LE(report.rpe.rot_rmse_rad, 1e-12);
}

TEST(EvaluateTrajectoryTest, ConstantYawOffset) {
  const std::vector<GroundTruthState> truth = Truth();
  const double yaw_offset = 0.01;
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  // Rz(d) Rz(yaw) Ry(pitch) Rx(roll) = Rz(yaw + d) Ry(pitch) Rx(roll): only yaw changes.
  for (StampedPose& pose : estimate) {
    pose.T_D_B.q = QuaternionFromRollPitchYaw(0.0, 0.0, yaw_offset) * pose.T_D_B.q;
  }
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_NEAR(report.overall.att_max_abs_rad.z(), yaw_offset, 1e-12);
  EXPECT_LE(report.overall.att_max_abs_rad.head<2>().maxCoeff(), 1e-12);
  EXPECT_NEAR(report.overall.att_rmse_rad, yaw_offset, 1e-12);
  EXPECT_LE(report.overall.pos_rmse_m, 1e-12);
}

TEST(EvaluateTrajectoryTest, InterpolatesTruthBetweenSamples) {
  // Truth at 10 Hz moving at constant velocity and turning at a constant rate about a fixed
  // axis: linear interpolation and slerp are exact for it.
  const Eigen::Vector3d p0(-15.0, 1.0, 4.0), v(0.4, -0.1, 0.05);
  const Eigen::Vector3d w = Eigen::Vector3d(0.1, -0.2, 0.3);
  const auto pose_at = [&](int64_t t_ns) {
    const double t = static_cast<double>(t_ns - kT0) * 1e-9;
    return Pose3(ExpQuaternion(w * t), p0 + v * t);
  };
  std::vector<GroundTruthState> truth(101);
  for (int i = 0; i < 101; ++i) {
    truth[i].t_ns = kT0 + i * (kSecond / 10);
    truth[i].T_D_B = pose_at(truth[i].t_ns);
  }
  Trajectory estimate;
  for (int64_t t = kT0 + 37'000'001; t < kT0 + 10 * kSecond; t += 33'333'333) {
    estimate.push_back({t, pose_at(t)});
  }
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(report.overall.n, static_cast<int>(estimate.size()));
  EXPECT_EQ(report.n_skipped, 0);  // the 0.1 s sample spacing is not a gap with the default
  ExpectAllZero(report.overall, 1e-12);
}

TEST(EvaluateTrajectoryTest, Se3AlignmentRemovesRigidOffset) {
  const std::vector<GroundTruthState> truth = Truth();
  const Pose3 T_est_true(QuaternionFromRollPitchYaw(0.05, -0.03, 0.2),
                         Eigen::Vector3d(1.0, -2.0, 0.5));
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  for (StampedPose& pose : estimate) pose.T_D_B = T_est_true * pose.T_D_B;

  EvaluationOptions options;
  const EvaluationReport unaligned = EvaluateTrajectory(truth, estimate, {}, options);
  EXPECT_GT(unaligned.overall.pos_rmse_m, 1.0);
  EXPECT_NEAR(unaligned.overall.att_rmse_rad,
              RotationAngleBetween(Eigen::Quaterniond::Identity(), T_est_true.q), 1e-9);

  options.alignment = Alignment::kSE3;
  const EvaluationReport aligned = EvaluateTrajectory(truth, estimate, {}, options);
  EXPECT_EQ(aligned.overall.n, kNumSamples);
  ExpectAllZero(aligned.overall, 1e-9);
  EXPECT_LE((aligned.alignment.Matrix() - T_est_true.Inverse().Matrix()).cwiseAbs().maxCoeff(),
            1e-9);
  // RPE does not depend on the estimate's frame.
  EXPECT_LE(unaligned.rpe.trans_rmse_m, 1e-9);
  EXPECT_LE(unaligned.rpe.rot_rmse_rad, 1e-9);
}

TEST(EvaluateTrajectoryTest, SplitsByVisibilityStage) {
  const std::vector<GroundTruthState> truth = Truth();
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  // An error only while only the mono camera sees the dock.
  for (StampedPose& pose : estimate) {
    if (pose.t_ns >= kT0 + 10 * kSecond && pose.t_ns < kT0 + 15 * kSecond) {
      pose.T_D_B.p.x() += 0.1;
    }
  }
  // Starts 1 s in (the first second is unknown), given out of order on purpose.
  const std::vector<VisibilityRecord> visibility = {
      Record(kT0 + 5 * kSecond, VisibilityStage::kBoth),
      Record(kT0 + 1 * kSecond, VisibilityStage::kStereoOnly),
      Record(kT0 + 3 * kSecond, VisibilityStage::kStereoOnly),
      Record(kT0 + 10 * kSecond, VisibilityStage::kMonoOnly),
      Record(kT0 + 15 * kSecond, VisibilityStage::kNeither),
  };
  const EvaluationReport report =
      EvaluateTrajectory(truth, estimate, visibility, EvaluationOptions());
  ASSERT_EQ(report.by_stage.size(), 5u);
  const VisibilityStage expected_stages[] = {VisibilityStage::kStereoOnly, VisibilityStage::kBoth,
                                             VisibilityStage::kMonoOnly, VisibilityStage::kNeither,
                                             VisibilityStage::kUnknown};
  const int expected_n[] = {400, 500, 500, 501, 100};
  int total = 0;
  for (int s = 0; s < 5; ++s) {
    EXPECT_EQ(report.by_stage[s].first, expected_stages[s]) << s;
    EXPECT_EQ(report.by_stage[s].second.n, expected_n[s]) << s;
    total += report.by_stage[s].second.n;
  }
  EXPECT_EQ(total, report.overall.n);
  EXPECT_NEAR(report.by_stage[2].second.pos_rmse_m, 0.1, 1e-12);
  EXPECT_NEAR(report.by_stage[2].second.pos_mean_m.x(), 0.1, 1e-12);
  for (int s : {0, 1, 3, 4}) EXPECT_LE(report.by_stage[s].second.pos_rmse_m, 1e-12) << s;
}

TEST(EvaluateTrajectoryTest, StagesWithoutPosesAreLeftOut) {
  const std::vector<GroundTruthState> truth = Truth();
  const std::vector<VisibilityRecord> visibility = {
      Record(kT0 - kSecond, VisibilityStage::kNeither)};
  const EvaluationReport report =
      EvaluateTrajectory(truth, test::TrajectoryFromTruth(truth), visibility, EvaluationOptions());
  ASSERT_EQ(report.by_stage.size(), 1u);
  EXPECT_EQ(report.by_stage[0].first, VisibilityStage::kNeither);
  EXPECT_EQ(report.by_stage[0].second.n, kNumSamples);
}

// The RPE of a drift of `rate` m/s along x of D, by direct enumeration of the pairs on the
// 100 Hz grid: step = delta, or the time to the last pose if that is within 10 % of delta.
// Each pair contributes E = (I, R_j^T (rate * step, 0, 0)), so |p(E)| = rate * step.
std::pair<int, double> ExpectedDriftRpe(double rate, int64_t delta_ns) {
  const int64_t end_ns = kT0 + (kNumSamples - 1) * kDt;
  int n_pairs = 0;
  double sum_sq = 0.0;
  for (int i = 0; i < kNumSamples; ++i) {
    const int64_t t_ns = kT0 + i * kDt;
    int64_t step_ns = delta_ns;
    if (t_ns + delta_ns > end_ns) {
      if (t_ns + delta_ns - end_ns > delta_ns / 10) continue;
      step_ns = end_ns - t_ns;
    }
    const double e = rate * static_cast<double>(step_ns) * 1e-9;
    sum_sq += e * e;
    ++n_pairs;
  }
  return {n_pairs, std::sqrt(sum_sq / n_pairs)};
}

TEST(EvaluateTrajectoryTest, RpeMeasuresDrift) {
  const std::vector<GroundTruthState> truth = Truth();
  const double rate = 0.01;  // m/s
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  for (StampedPose& pose : estimate) {
    pose.T_D_B.p.x() += rate * static_cast<double>(pose.t_ns - kT0) * 1e-9;
  }
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  const auto [n_one, rmse_one] = ExpectedDriftRpe(rate, kSecond);
  EXPECT_EQ(n_one, kNumSamples - 90);
  EXPECT_EQ(report.rpe.n_pairs, n_one);
  EXPECT_NEAR(report.rpe.trans_rmse_m, rmse_one, 1e-12);
  EXPECT_NEAR(report.rpe.trans_rmse_m, rate, 1e-5);  // almost all pairs are exactly 1 s apart
  EXPECT_LE(report.rpe.rot_rmse_rad, 1e-12);

  EvaluationOptions options;
  options.rpe_delta_s = 2.0;
  const EvaluationReport two_s = EvaluateTrajectory(truth, estimate, {}, options);
  const auto [n_two, rmse_two] = ExpectedDriftRpe(rate, 2 * kSecond);
  EXPECT_EQ(n_two, kNumSamples - 180);
  EXPECT_EQ(two_s.rpe.n_pairs, n_two);
  EXPECT_EQ(two_s.rpe.delta_s, 2.0);
  EXPECT_NEAR(two_s.rpe.trans_rmse_m, rmse_two, 1e-12);
}

TEST(EvaluateTrajectoryTest, RpePairsNeedAPoseNearDelta) {
  const std::vector<GroundTruthState> truth = Truth();
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  estimate.resize(50);  // 0.49 s, shorter than delta: no pair
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(report.rpe.n_pairs, 0);
  EXPECT_TRUE(std::isnan(report.rpe.trans_rmse_m));
  EXPECT_TRUE(std::isnan(report.rpe.rot_rmse_rad));

  // Poses every 0.3 s: for delta = 1 s the candidates are +0.9 s (misses by exactly the 10 %
  // tolerance: used) and +1.2 s (misses by 20 %).
  Trajectory sparse;
  for (int64_t t = kT0; t <= kT0 + 3 * kSecond; t += 300'000'000) sparse.push_back({t, {}});
  const EvaluationReport sparse_report = EvaluateTrajectory(truth, sparse, {}, EvaluationOptions());
  // Pairs (0, 0.9), (0.3, 1.2), ..., (2.1, 3.0): 8 pairs.
  EXPECT_EQ(sparse_report.rpe.n_pairs, 8);
}

TEST(EvaluateTrajectoryTest, CountsPosesOutsideTheTruthAsSkipped) {
  const std::vector<GroundTruthState> truth = Truth();
  Trajectory estimate;
  for (int i = 5; i > 0; --i) estimate.push_back({kT0 - i * kDt, Pose3()});
  const Trajectory inside = test::TrajectoryFromTruth(truth);
  estimate.insert(estimate.end(), inside.begin(), inside.end());
  for (int i = 1; i <= 3; ++i) estimate.push_back({truth.back().t_ns + i, Pose3()});
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(report.n_skipped, 8);
  EXPECT_EQ(report.overall.n, kNumSamples);
  ExpectAllZero(report.overall, 1e-12);
}

TEST(EvaluateTrajectoryTest, SkipsPosesInTruthGaps) {
  std::vector<GroundTruthState> truth = Truth();
  // Remove the truth in (5 s, 6 s): a 1 s gap between the samples at 5 s and 6 s.
  truth.erase(truth.begin() + 501, truth.begin() + 600);
  const Trajectory estimate = test::TrajectoryFromTruth(Truth());
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(report.n_skipped, 99);
  EXPECT_EQ(report.overall.n, kNumSamples - 99);

  EvaluationOptions no_gap_limit;
  no_gap_limit.max_truth_gap_s = std::numeric_limits<double>::infinity();
  EXPECT_EQ(EvaluateTrajectory(truth, estimate, {}, no_gap_limit).n_skipped, 0);
}

TEST(EvaluateTrajectoryTest, RejectsUnusableInput) {
  const std::vector<GroundTruthState> truth = Truth();
  const Trajectory estimate = test::TrajectoryFromTruth(truth);
  EXPECT_EQ(EvaluationError({}, estimate), "dataset has no ground truth");

  Trajectory later;
  later.push_back({truth.back().t_ns + kSecond, Pose3()});
  EXPECT_THAT(EvaluationError(truth, later),
              HasSubstr("estimate has no pose within the ground-truth time span"));
  EXPECT_THAT(EvaluationError(truth, Trajectory()),
              HasSubstr("estimate has no pose within the ground-truth time span"));

  EvaluationOptions bad_delta;
  bad_delta.rpe_delta_s = 0.0;
  EXPECT_THAT(EvaluationError(truth, estimate, bad_delta), HasSubstr("RPE delta"));

  Trajectory unordered = estimate;
  std::swap(unordered[3], unordered[4]);
  EXPECT_THAT(EvaluationError(truth, unordered), HasSubstr("not strictly increasing"));

  // SE(3) alignment on a single matched pose is impossible.
  EvaluationOptions se3;
  se3.alignment = Alignment::kSE3;
  EXPECT_THAT(EvaluationError(truth, Trajectory(estimate.begin(), estimate.begin() + 1), se3),
              HasSubstr("non-collinear"));
}

// NEES with a known answer: the estimate is the truth moved by e = Sigma^1/2 z for a fixed
// unit vector z in the PoseManifold tangent, so every pose's NEES is |z|^2 = 1 exactly; with
// z scaled by 4 it is 16 (> 12.59, all above the 95 % point). Poses without a covariance are not
// counted, and an alignment is refused.
TEST(EvaluateTrajectoryTest, NeesOfAKnownErrorAndItsCounts) {
  const std::vector<GroundTruthState> truth = Truth();
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
  A(0, 1) = 0.3;
  A(4, 2) = -0.2;
  const Eigen::Matrix<double, 6, 6> sqrt_sigma = 0.01 * A;  // Sigma = S S^T
  Eigen::Matrix<double, 6, 1> z;
  z << 0.5, -0.5, 0.5, 0.1, -0.3, 0.4;
  z.normalize();
  for (const double scale : {1.0, 4.0}) {
    const Eigen::Matrix<double, 6, 1> e = sqrt_sigma * (scale * z);
    Trajectory estimate = test::TrajectoryFromTruth(truth);
    std::vector<StampedPoseCovariance> covariances;
    for (size_t k = 0; k < estimate.size(); ++k) {
      StampedPose& pose = estimate[k];
      pose.T_D_B.p += e.head<3>();
      pose.T_D_B.q = ExpQuaternion(e.tail<3>()) * pose.T_D_B.q;
      if (k % 2 == 0) covariances.push_back({pose.t_ns, sqrt_sigma * sqrt_sigma.transpose()});
    }
    const EvaluationReport report =
        EvaluateTrajectory(truth, estimate, {}, EvaluationOptions(), {covariances, {}, {}});
    EXPECT_EQ(report.overall.nees_n, static_cast<int>(covariances.size()));
    EXPECT_NEAR(report.overall.nees_mean, scale * scale, 1e-6);
    EXPECT_DOUBLE_EQ(report.overall.nees_above_95, scale > 1.0 ? 1.0 : 0.0);
  }
  EvaluationOptions aligned;
  aligned.alignment = Alignment::kSE3;
  const Trajectory estimate = test::TrajectoryFromTruth(truth);
  EstimateReports one_covariance;
  one_covariance.covariances = {{estimate[0].t_ns, Eigen::Matrix<double, 6, 6>::Identity()}};
  EXPECT_THROW(EvaluateTrajectory(truth, estimate, {}, aligned, one_covariance), InputError);
  // Without covariances the NEES fields say "none".
  const EvaluationReport plain = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(plain.overall.nees_n, 0);
  EXPECT_TRUE(std::isnan(plain.overall.nees_mean));
}

// A known bound at every third pose: its RMS, and the estimate's errors over those poses only.
TEST(EvaluateTrajectoryTest, BoundRmsBesideTheErrorsOverTheSamePoses) {
  const std::vector<GroundTruthState> truth = Truth();
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  EstimateReports reports;
  Eigen::Matrix<double, 6, 1> diagonal;
  diagonal << 1e-4, 1e-4, 2e-4, 1e-6, 2e-6, 1e-6;  // tr P_p = 4e-4 m^2, tr P_theta = 4e-6 rad^2
  for (size_t k = 0; k < estimate.size(); ++k) {
    StampedPose& pose = estimate[k];
    if (k % 3 == 0) {
      pose.T_D_B.p.x() += 0.03;  // 3 cm off where there is a bound
      pose.T_D_B.q = ExpQuaternion(Eigen::Vector3d(0.0, 0.0, 0.004)) * pose.T_D_B.q;
      reports.bounds.push_back({pose.t_ns, Eigen::Matrix<double, 6, 6>(diagonal.asDiagonal())});
    }
  }
  const EvaluationReport report =
      EvaluateTrajectory(truth, estimate, {}, EvaluationOptions(), reports);
  EXPECT_EQ(report.overall.bound_n, static_cast<int>(reports.bounds.size()));
  EXPECT_NEAR(report.overall.bound_pos_rms_m, 0.02, 1e-12);
  EXPECT_NEAR(report.overall.bound_att_rms_rad, 0.002, 1e-12);
  EXPECT_NEAR(report.overall.pos_rmse_at_bound_m, 0.03, 1e-12);
  EXPECT_NEAR(report.overall.att_rmse_at_bound_rad, 0.004, 1e-9);
  EXPECT_NEAR(report.overall.pos_rmse_m, 0.03 / std::sqrt(3.0), 1e-3);  // all poses
  // Without a bound the fields say "none"; with an alignment a bound is refused.
  const EvaluationReport plain = EvaluateTrajectory(truth, estimate, {}, EvaluationOptions());
  EXPECT_EQ(plain.overall.bound_n, 0);
  EXPECT_TRUE(std::isnan(plain.overall.bound_pos_rms_m));
  EvaluationOptions aligned;
  aligned.alignment = Alignment::kSE3;
  EXPECT_THROW(EvaluateTrajectory(truth, estimate, {}, aligned, reports), InputError);
}

// The audit with known errors: poses 0..9 are off by 0.06 m in x and 0.08 m in y (0.10 m
// lateral, at the limit: safe), poses 10..19 by 0.12 m in x (unsafe), the rest exact. GO at
// every even pose, one GO at a time with no pose, NO-GO elsewhere.
TEST(EvaluateTrajectoryTest, DecisionAuditCountsUnsafeGo) {
  const std::vector<GroundTruthState> truth = Truth();
  Trajectory estimate = test::TrajectoryFromTruth(truth);
  EstimateReports reports;
  for (size_t k = 0; k < 40; ++k) {
    if (k < 10) estimate[k].T_D_B.p += Eigen::Vector3d(0.06, 0.08, 0.5);  // z does not count
    if (k >= 10 && k < 20) estimate[k].T_D_B.p.x() += 0.12;
    reports.decisions.push_back({estimate[k].t_ns, k % 2 == 0, "test"});
  }
  reports.decisions.push_back({estimate[40].t_ns + 1, true, "a GO between poses"});
  EvaluationOptions options;
  options.allowed_lateral_error_m = 0.10 + 1e-9;
  const EvaluationReport report = EvaluateTrajectory(truth, estimate, {}, options, reports);
  const DecisionAudit& a = report.decisions;
  EXPECT_EQ(a.n_go, 21);
  EXPECT_EQ(a.n_no_go, 20);
  EXPECT_EQ(a.n_go_unsafe, 5);  // poses 10, 12, 14, 16, 18
  EXPECT_EQ(a.n_go_unmatched, 1);
  EXPECT_NEAR(a.max_lateral_error_at_go_m, 0.12, 1e-12);
  EXPECT_NEAR(a.max_yaw_error_at_go_rad, 0.0, 1e-9);
}

TEST(AlignmentNameTest, RoundTrips) {
  for (Alignment a : {Alignment::kNone, Alignment::kSE3}) {
    Alignment parsed = a == Alignment::kNone ? Alignment::kSE3 : Alignment::kNone;
    EXPECT_TRUE(ParseAlignment(AlignmentName(a), &parsed));
    EXPECT_EQ(parsed, a);
  }
  Alignment unused;
  EXPECT_FALSE(ParseAlignment("sim3", &unused));
}

// White values are worth one each; values that each repeat 5 times are worth a fifth:
// rho_k = (5 - k) / 5 for k < 5, so tau = 1 + 2 (0.8 + 0.6 + 0.4 + 0.2) = 5.
TEST(IntegratedAutocorrelationTimeTest, WhiteValuesAndRepeatedValues) {
  std::mt19937 rng(7);
  std::chi_squared_distribution<double> chi2(6.0);
  std::vector<double> white, repeated;
  for (int i = 0; i < 4000; ++i) white.push_back(chi2(rng));
  for (int i = 0; i < 4000; ++i) {
    const double x = chi2(rng);
    for (int r = 0; r < 5; ++r) repeated.push_back(x);
  }
  EXPECT_NEAR(IntegratedAutocorrelationTime(white), 1.0, 0.1);
  EXPECT_NEAR(IntegratedAutocorrelationTime(repeated), 5.0, 0.3);
  EXPECT_TRUE(std::isnan(IntegratedAutocorrelationTime({3.0})));
  EXPECT_TRUE(std::isnan(IntegratedAutocorrelationTime({2.0, 2.0, 2.0})));
}

}  // namespace
}  // namespace auvdock
