// The Cramér–Rao bound against Monte-Carlo errors: over seeded synthetic runs of the default
// scenario (white 0.3 px pixel noise, the simulated IMU), the batch smoother's pose errors
// measured with the bound instead of its own covariance,
//   ANEES_k = 1/N sum_runs e_k^T B_k^-1 e_k,
// average 6 when the smoother attains the bound (an efficient estimator: least squares with
// small Gaussian noise does) and the bound is right: a bound too small by a factor c in variance
// gives 6 c, too large 6 / c. Asserted: the mean over the lit frames after the first 2 s is within
// the chi-square(6N)/N 95 % band widened by 15 % (the smoother's Huber loss and the
// linearisation leave it a little above the bound).
#include <cmath>
#include <cstdio>
#include <map>

#include <gtest/gtest.h>

#include "auvdock/estimator/cramer_rao_bound.h"
#include "tests/testing/synthetic_vision.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

// The p-quantile of chi-square with k degrees of freedom (Wilson-Hilferty), z the standard
// normal quantile of p.
double ChiSquareQuantile(double z, int k) {
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3);
}

TEST(CramerRaoConsistencyTest, TheSmoothersErrorsAttainTheBound) {
  constexpr int kRuns = 8;
  EstimatorOptions white;
  white.smoother_vision_floor_px = 0.0;
  std::map<int64_t, std::pair<double, int>> by_time;  // sum of NEES, runs
  for (uint64_t seed = 1; seed <= kRuns; ++seed) {
    const test::SyntheticRun run = test::MakeSyntheticRun(test::DefaultScenario(), seed);
    SlidingWindowEstimator estimator(run.calibration, run.dock, white);
    test::RunWindow(run, &estimator);
    const BatchResult batch = SmoothBatch(run.calibration, run.dock, run.frames, run.imu,
                                          estimator.History(), white);
    const CramerRaoBound bound =
        ComputeCramerRaoBound(run.calibration, run.dock, run.frames, run.imu, run.states, white);
    std::map<int64_t, size_t> frame_at;
    for (size_t k = 0; k < run.frames.size(); ++k) frame_at[run.frames[k].t_ns] = k;
    std::map<int64_t, const Eigen::Matrix<double, 6, 6>*> bound_at;
    for (const StampedPoseCovariance& b : bound.poses) bound_at[b.t_ns] = &b.covariance;
    for (const EstimatorOutput& out : batch.outputs) {
      const size_t k = frame_at.at(out.t_ns);
      const VisionFrame& frame = run.frames[k];
      if (k < 20 || (frame.mono.size() < 3 && frame.stereo.size() < 3)) continue;
      const auto b = bound_at.find(out.t_ns);
      ASSERT_NE(b, bound_at.end());
      const Pose3& truth = run.truth[k].T_D_B;
      Eigen::Matrix<double, 6, 1> e;
      e.head<3>() = out.T_D_B.p - truth.p;
      const Eigen::AngleAxisd aa(out.T_D_B.q * truth.q.conjugate());
      e.tail<3>() = aa.angle() * aa.axis();
      auto& [sum, runs] = by_time[out.t_ns];
      sum += e.dot(b->second->ldlt().solve(e));
      ++runs;
    }
  }
  double total = 0.0;
  int times = 0;
  for (const auto& [t, entry] : by_time) {
    if (entry.second != kRuns) continue;
    total += entry.first / kRuns;
    ++times;
  }
  ASSERT_GT(times, 250);
  const double mean = total / times;
  const double low = ChiSquareQuantile(-1.959964, 6 * kRuns) / kRuns;
  const double high = ChiSquareQuantile(1.959964, 6 * kRuns) / kRuns;
  std::printf("smoother against the bound: %d runs, %d times, mean ANEES %.2f (band %.2f-%.2f)\n",
              kRuns, times, mean, low, high);
  EXPECT_GE(mean, low / 1.15);
  EXPECT_LE(mean, high * 1.15);
}

}  // namespace
}  // namespace auvdock
