#include "auvdock/estimator/depth_second_difference.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

DepthMeasurement At(double t_s, double depth_m) {
  DepthMeasurement m;
  m.t_ns = static_cast<int64_t>(std::llround(t_s * 1e9));
  m.depth_m = depth_m;
  return m;
}

TEST(DepthSecondDifference, ASmoothDescentGivesItsAccelerationUnevenlySpaced) {
  // z = 30 + 0.2 t + 0.05 t^2: the second difference is 0.1 m/s^2 at any spacing.
  DepthSecondDifferenceOptions options;
  options.accel_sigma_mps2 = 0.0;
  DepthSecondDifference innovation(options);
  const auto z = [](double t) { return 30.0 + 0.2 * t + 0.05 * t * t; };
  EXPECT_FALSE(innovation.Add(At(0.0, z(0.0)), 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(At(0.1, z(0.1)), 0.02, 1.0));
  const std::optional<double> s = innovation.Add(At(0.25, z(0.25)), 0.02, 1.0);
  ASSERT_TRUE(s);
  // c0 = 2 / (0.1 * 0.25), c2 = 2 / (0.15 * 0.25), c1 = -c0 - c2.
  const double c0 = 80.0, c2 = 2.0 / 0.0375, c1 = -c0 - c2;
  const double variance = 0.02 * 0.02 * (c0 * c0 + c1 * c1 + c2 * c2);
  EXPECT_NEAR(*s, 0.1 * 0.1 / variance, 1e-9);
}

TEST(DepthSecondDifference, WhiteNoiseAtTheGivenSigmaHasAMeanStatisticOfOneTimesTheRatio) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.06);  // three times the configured 0.02
  for (const double lambda : {1.0, 9.0}) {
    DepthSecondDifference innovation;
    double sum = 0.0;
    int n = 0;
    for (int k = 0; k < 20000; ++k) {
      if (auto s = innovation.Add(At(0.1 * k, 30.0 + noise(rng)), 0.02, lambda)) {
        sum += *s;
        ++n;
      }
    }
    EXPECT_EQ(n, 19998);
    EXPECT_NEAR(sum / n, 9.0 / lambda, 0.05 * 9.0 / lambda);
  }
}

TEST(DepthSecondDifference, AGapRestartsAndABackwardSampleIsIgnored) {
  DepthSecondDifference innovation;
  EXPECT_FALSE(innovation.Add(At(0.0, 30.0), 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(At(0.1, 30.0), 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(At(0.05, 30.0), 0.02, 1.0));  // backwards: ignored
  EXPECT_TRUE(innovation.Add(At(0.2, 30.0), 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(At(5.0, 30.0), 0.02, 1.0));   // a gap: a new triple
  EXPECT_FALSE(innovation.Add(At(5.1, 30.0), 0.02, 1.0));
  EXPECT_TRUE(innovation.Add(At(5.2, 30.0), 0.02, 1.0));
  DepthMeasurement nan = At(5.3, std::nan(""));
  EXPECT_FALSE(innovation.Add(nan, 0.02, 1.0));
}

}  // namespace
}  // namespace auvdock
