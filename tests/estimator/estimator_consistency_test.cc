// Consistency of the reported covariances of the sliding window (20 seeded runs of the default
// docking scenario) and of the batch smoother (10 runs), with synthetic identified lights
// (0.3 px white noise) and the simulated IMU: the mean NEES of the 6-DoF pose over the frames
// where a camera system sees at least 3 lights should be near 6 (the dimension). The per-run
// means are printed; the assertion is a loose band because the frames of a run are strongly
// correlated, so the chi-square band of independent samples would be far too narrow.
#include <cstdio>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "auvdock/estimator/batch_smoother.h"
#include "auvdock/estimator/sliding_window_estimator.h"
#include "tests/testing/synthetic_vision.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

TEST(EstimatorConsistencyTest, MeanPoseNeesOverTwentySeedsIsNearSix) {
  const Scenario scenario = test::DefaultScenario();
  double sum = 0.0;
  int count = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const test::SyntheticRun run = test::MakeSyntheticRun(scenario, seed);
    SlidingWindowEstimator estimator(run.calibration, run.dock);
    size_t next_imu = 0;
    double run_sum = 0.0;
    int run_count = 0;
    for (size_t k = 0; k < run.frames.size(); ++k) {
      const VisionFrame& frame = run.frames[k];
      while (next_imu < run.imu.size() && run.imu[next_imu].t_ns <= frame.t_ns) {
        estimator.AddImu(run.imu[next_imu++]);
      }
      const std::optional<EstimatorOutput> out = estimator.AddVisionFrame(frame);
      if (!out || !out->covariance_ok || k < 20) continue;  // the first 2 s: initialisation
      if (frame.mono.size() < 3 && frame.stereo.size() < 3) continue;
      const Pose3& truth = run.truth[k].T_D_B;
      Eigen::Matrix<double, 6, 1> e;
      e.head<3>() = out->T_D_B.p - truth.p;
      const Eigen::AngleAxisd aa(out->T_D_B.q * truth.q.conjugate());
      e.tail<3>() = aa.angle() * aa.axis();
      run_sum += e.dot(out->covariance.ldlt().solve(e));
      ++run_count;
    }
    ASSERT_GT(run_count, 250) << seed;
    std::printf("seed %2llu: mean NEES %.2f over %d frames\n",
                static_cast<unsigned long long>(seed), run_sum / run_count, run_count);
    sum += run_sum;
    count += run_count;
  }
  const double mean = sum / count;
  std::printf("mean NEES over 20 seeds: %.3f (%d frames)\n", mean, count);
  EXPECT_GT(mean, 4.5);
  EXPECT_LT(mean, 8.0);
}

// The same for the batch smoother's covariance over 10 seeds (every state sees the data on
// both sides, so its covariance is smaller; with white measurement noise it must still be
// honest).
TEST(EstimatorConsistencyTest, MeanSmootherPoseNeesOverTenSeedsIsNearSix) {
  const Scenario scenario = test::DefaultScenario();
  double sum = 0.0;
  int count = 0;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const test::SyntheticRun run = test::MakeSyntheticRun(scenario, seed);
    SlidingWindowEstimator estimator(run.calibration, run.dock);
    size_t next_imu = 0;
    for (const VisionFrame& frame : run.frames) {
      while (next_imu < run.imu.size() && run.imu[next_imu].t_ns <= frame.t_ns) {
        estimator.AddImu(run.imu[next_imu++]);
      }
      estimator.AddVisionFrame(frame);
    }
    const BatchResult batch = SmoothBatch(run.calibration, run.dock, run.frames, run.imu,
                                          estimator.History(), EstimatorOptions());
    ASSERT_GT(batch.outputs.size(), run.frames.size() - 20) << seed;
    std::map<int64_t, size_t> frame_at;  // the run may start a few frames late
    for (size_t k = 0; k < run.frames.size(); ++k) frame_at[run.frames[k].t_ns] = k;
    double run_sum = 0.0;
    int run_count = 0;
    for (const EstimatorOutput& out : batch.outputs) {
      const size_t k = frame_at.at(out.t_ns);
      if (!out.covariance_ok || k < 20) continue;
      if (run.frames[k].mono.size() < 3 && run.frames[k].stereo.size() < 3) continue;
      const Pose3& truth = run.truth[k].T_D_B;
      Eigen::Matrix<double, 6, 1> e;
      e.head<3>() = out.T_D_B.p - truth.p;
      const Eigen::AngleAxisd aa(out.T_D_B.q * truth.q.conjugate());
      e.tail<3>() = aa.angle() * aa.axis();
      run_sum += e.dot(out.covariance.ldlt().solve(e));
      ++run_count;
    }
    ASSERT_GT(run_count, 250) << seed;
    std::printf("seed %2llu: smoother mean NEES %.2f over %d frames\n",
                static_cast<unsigned long long>(seed), run_sum / run_count, run_count);
    sum += run_sum;
    count += run_count;
  }
  const double mean = sum / count;
  std::printf("smoother mean NEES over 10 seeds: %.3f (%d frames)\n", mean, count);
  EXPECT_GT(mean, 4.5);
  EXPECT_LT(mean, 8.0);
}

}  // namespace
}  // namespace auvdock
