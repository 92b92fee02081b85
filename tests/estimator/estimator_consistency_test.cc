// Consistency of the sliding window's reported covariance over 20 seeded runs of the default
// docking scenario (synthetic identified lights, 0.3 px noise, simulated IMU): the mean NEES of
// the 6-DoF pose over the frames where a camera system sees at least 3 lights should be near 6
// (the dimension). The per-run means are printed; the assertion is a loose band because the
// frames of a run are strongly correlated (a fixed-lag smoother's errors are), so the
// chi-square band of independent samples would be far too narrow.
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace auvdock
