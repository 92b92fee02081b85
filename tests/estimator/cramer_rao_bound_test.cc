// The Cramér–Rao bound (estimator/cramer_rao_bound.h): the true state between truth samples, a
// known answer (a lone state bounded by its prior alone), and the bound as the information of
// the smoother's own problem (at the truth it is the smoother's reported covariance, to the
// linearisation point's difference).
#include <cmath>
#include <map>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "auvdock/estimator/cramer_rao_bound.h"
#include "factors/pose_manifold.h"
#include "tests/testing/synthetic_vision.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

GroundTruthState State(int64_t t_ns, double x, double yaw, double vx, double bg) {
  GroundTruthState s;
  s.t_ns = t_ns;
  s.T_D_B = Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())),
                  Eigen::Vector3d(x, 1.0, 2.0));
  s.v_D = Eigen::Vector3d(vx, 0.0, 0.0);
  s.gyro_bias = Eigen::Vector3d::Constant(bg);
  s.accel_bias = Eigen::Vector3d::Constant(2.0 * bg);
  return s;
}

TEST(TrueStateAtTest, InterpolatesBetweenSamplesAndRefusesOutsideAndInGaps) {
  const std::vector<GroundTruthState> truth = {State(0, 0.0, 0.0, 1.0, 0.0),
                                               State(100'000'000, 1.0, 0.4, 3.0, 0.02),
                                               State(1'000'000'000, 2.0, 0.4, 3.0, 0.02)};
  const std::optional<StateRecord> mid = TrueStateAt(truth, 25'000'000, 0.1);
  ASSERT_TRUE(mid);
  const Pose3 T = PoseFromBlock(mid->pose);
  EXPECT_NEAR(T.p.x(), 0.25, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(T.q).angle(), 0.1, 1e-12);
  EXPECT_NEAR(mid->velocity[0], 1.5, 1e-12);
  EXPECT_NEAR(mid->bias[0], 0.005, 1e-12);
  EXPECT_NEAR(mid->bias[3], 0.01, 1e-12);
  const std::optional<StateRecord> on = TrueStateAt(truth, 100'000'000, 0.1);
  ASSERT_TRUE(on);
  EXPECT_EQ(PoseFromBlock(on->pose).p.x(), 1.0);
  EXPECT_FALSE(TrueStateAt(truth, -1, 0.1));             // before the truth
  EXPECT_FALSE(TrueStateAt(truth, 1'000'000'001, 0.1));  // after it
  EXPECT_FALSE(TrueStateAt(truth, 500'000'000, 0.1));    // in a 0.9 s gap
  EXPECT_TRUE(TrueStateAt(truth, 500'000'000, 1.0));
}

TEST(CramerRaoBoundTest, ALoneStateWithoutMeasurementsIsBoundedByItsPrior) {
  const test::SyntheticRun run = test::MakeSyntheticRun(test::DefaultScenario(), 1);
  VisionFrame frame;
  frame.t_ns = run.frames.front().t_ns;  // no lights: the prior is all there is
  EstimatorOptions options;
  options.init_position_sigma_m = 0.4;
  options.init_attitude_sigma_rad = 0.1;
  const CramerRaoBound bound =
      ComputeCramerRaoBound(run.calibration, run.dock, {frame}, {}, run.states, options);
  ASSERT_EQ(bound.poses.size(), 1u);
  EXPECT_EQ(bound.poses[0].t_ns, frame.t_ns);
  Eigen::Matrix<double, 6, 1> prior;
  prior << 0.16, 0.16, 0.16, 0.01, 0.01, 0.01;
  EXPECT_LT((bound.poses[0].covariance - Eigen::Matrix<double, 6, 6>(prior.asDiagonal())).norm(),
            1e-9);
}

TEST(CramerRaoBoundTest, IsTheSmoothersInformationAtTheTruth) {
  const test::SyntheticRun run = test::MakeSyntheticRun(test::DefaultScenario(), 3);
  EstimatorOptions white;  // the data are white: no allowance for correlated pixel errors
  white.smoother_vision_floor_px = 0.0;
  SlidingWindowEstimator estimator(run.calibration, run.dock, white);
  test::RunWindow(run, &estimator);
  const BatchResult batch = SmoothBatch(run.calibration, run.dock, run.frames, run.imu,
                                        estimator.History(), white);
  const CramerRaoBound bound =
      ComputeCramerRaoBound(run.calibration, run.dock, run.frames, run.imu, run.states, white);
  EXPECT_EQ(bound.frames, static_cast<int>(run.frames.size()));
  EXPECT_EQ(bound.frames_without_truth, 0);
  EXPECT_EQ(bound.covariance_failures, 0);
  ASSERT_EQ(bound.poses.size(), run.frames.size());  // a state at every frame, lit or not
  std::map<int64_t, const Eigen::Matrix<double, 6, 6>*> bound_at;
  for (const StampedPoseCovariance& b : bound.poses) bound_at[b.t_ns] = &b.covariance;
  std::map<int64_t, const VisionFrame*> frame_at;
  for (const VisionFrame& f : run.frames) frame_at[f.t_ns] = &f;
  // Over the smoother's poses where lights are seen: the same problem at a nearby point, so
  // nearly the same covariance (the Jacobians change little between the estimate and the
  // truth). Not in the unlit end of the run: there the IMU alone carries the pose, the
  // smoother's errors outgrow its covariance (its IMU Jacobians at a drifted estimate), and the
  // two differ (cramer_rao_consistency_test.cc measures the errors against the bound).
  double smoother_trace = 0.0, bound_trace = 0.0;
  int n = 0;
  for (const EstimatorOutput& out : batch.outputs) {
    const VisionFrame& frame = *frame_at.at(out.t_ns);
    if (!out.covariance_ok || (frame.mono.size() < 3 && frame.stereo.size() < 3)) continue;
    const auto b = bound_at.find(out.t_ns);
    ASSERT_NE(b, bound_at.end());
    smoother_trace += out.covariance.topLeftCorner<3, 3>().trace();
    bound_trace += b->second->topLeftCorner<3, 3>().trace();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(*b->second);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    ++n;
  }
  ASSERT_GT(n, 250);
  EXPECT_NEAR(bound_trace / smoother_trace, 1.0, 0.03);
  // Without vision the bound is far wider: the lights carry the information.
  std::vector<VisionFrame> unlit;
  for (const VisionFrame& f : run.frames) {
    unlit.emplace_back();
    unlit.back().t_ns = f.t_ns;
  }
  const CramerRaoBound blind =
      ComputeCramerRaoBound(run.calibration, run.dock, unlit, run.imu, run.states, white);
  ASSERT_EQ(blind.poses.size(), bound.poses.size());
  const auto position_trace = [](const StampedPoseCovariance& p) {
    return p.covariance.topLeftCorner<3, 3>().trace();
  };
  EXPECT_GT(position_trace(blind.poses[200]), 100.0 * position_trace(bound.poses[200]));
}

}  // namespace
}  // namespace auvdock
