#include "auvdock/estimator/second_difference.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

int64_t Ns(double t_s) { return static_cast<int64_t>(std::llround(t_s * 1e9)); }

TEST(SecondDifference, ASmoothDescentGivesItsAccelerationUnevenlySpaced) {
  // z = 30 + 0.2 t + 0.05 t^2: the second difference is 0.1 m/s^2 at any spacing.
  SecondDifferenceOptions options;
  options.accel_sigma = 0.0;
  SecondDifference innovation(options);
  const auto z = [](double t) { return 30.0 + 0.2 * t + 0.05 * t * t; };
  EXPECT_FALSE(innovation.Add(Ns(0.0), z(0.0), 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(0.1), z(0.1), 0.02, 1.0));
  const std::optional<double> s = innovation.Add(Ns(0.25), z(0.25), 0.02, 1.0);
  ASSERT_TRUE(s);
  // c0 = 2 / (0.1 * 0.25), c2 = 2 / (0.15 * 0.25), c1 = -c0 - c2.
  const double c0 = 80.0, c2 = 2.0 / 0.0375, c1 = -c0 - c2;
  const double variance = 0.02 * 0.02 * (c0 * c0 + c1 * c1 + c2 * c2);
  EXPECT_NEAR(*s, 0.1 * 0.1 / variance, 1e-9);
}

TEST(SecondDifference, WhiteNoiseAtTheGivenSigmaHasAMeanStatisticOfOneTimesTheRatio) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.06);  // three times the configured 0.02
  for (const double lambda : {1.0, 9.0}) {
    SecondDifference innovation;
    double sum = 0.0;
    int n = 0;
    for (int k = 0; k < 20000; ++k) {
      if (auto s = innovation.Add(Ns(0.1 * k), 30.0 + noise(rng), 0.02, lambda)) {
        sum += *s;
        ++n;
      }
    }
    EXPECT_EQ(n, 19998);
    EXPECT_NEAR(sum / n, 9.0 / lambda, 0.05 * 9.0 / lambda);
  }
}

// Slant ranges whose sigma grows with the range (each sample its own), three times noisier than
// their sigmas say, at 2 Hz with dropouts: the mean statistic is still 9.
TEST(SecondDifference, EachSampleWithItsOwnSigma) {
  std::mt19937_64 rng(4);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::bernoulli_distribution dropout(0.1);
  SecondDifferenceOptions options;
  options.max_span_s = 2.5;
  SecondDifference innovation(options);
  double sum = 0.0;
  int n = 0;
  for (int k = 0; k < 40000; ++k) {
    if (dropout(rng)) continue;
    const double t = 0.5 * k;
    const double range = 20.0 + 10.0 * std::sin(0.001 * t);  // slow: its curvature is negligible
    const double sigma = 0.05 + 0.005 * range;
    if (auto s = innovation.Add(Ns(t), range + 3.0 * sigma * unit(rng), sigma, 1.0)) {
      sum += *s;
      ++n;
    }
  }
  EXPECT_GT(n, 25000);
  EXPECT_NEAR(sum / n, 9.0, 0.45);
}

TEST(SecondDifference, AGapRestartsAndABackwardOrInvalidSampleIsIgnored) {
  SecondDifference innovation;
  EXPECT_FALSE(innovation.Add(Ns(0.0), 30.0, 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(0.1), 30.0, 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(0.05), 30.0, 0.02, 1.0));  // backwards: ignored
  EXPECT_TRUE(innovation.Add(Ns(0.2), 30.0, 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(5.0), 30.0, 0.02, 1.0));   // a gap: a new triple
  EXPECT_FALSE(innovation.Add(Ns(5.1), 30.0, 0.02, 1.0));
  EXPECT_TRUE(innovation.Add(Ns(5.2), 30.0, 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(5.3), std::nan(""), 0.02, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(5.3), 30.0, 0.0, 1.0));
  EXPECT_FALSE(innovation.Add(Ns(5.3), 30.0, -0.02, 1.0));
  EXPECT_TRUE(innovation.Add(Ns(5.3), 30.0, 0.02, 1.0));  // the invalid ones left no trace
}

// One outlier among constant samples: it is in three triples; the middle one's statistic (4x)
// is above the cutoff, and none of the three is returned, while the clean ones are, one late.
TEST(SecondDifference, AnOutlierSampleIsKeptOutOfAllThreeOfItsTriples) {
  SecondDifferenceOptions options;
  options.accel_sigma = 0.0;
  options.outlier_cutoff = 43.0;
  SecondDifference innovation(options);
  SecondDifference plain(SecondDifferenceOptions{0.0, 1.0});
  std::vector<int> returned, plain_large;
  for (int k = 0; k < 12; ++k) {
    // 0.2 m on a 0.02 m sigma at sample 6: 0.2^2 / (6 0.02^2) = 16.7 beside, 67 in the middle.
    const double z = 10.0 + (k == 6 ? 0.2 : 0.001 * (k % 2));
    if (innovation.Add(Ns(0.5 * k), z, 0.02, 1.0)) returned.push_back(k);
    const std::optional<double> s = plain.Add(Ns(0.5 * k), z, 0.02, 1.0);
    if (s && *s > 10.0) plain_large.push_back(k);
  }
  // Triples end at samples 2..11; those ending at 6, 7, 8 hold the outlier. Each statistic is
  // returned with the next sample: those of the triples ending at 2-5 at 3-6, at 9-10 at 10-11
  // (the one ending at 5 is returned at 6, before the outlier shows).
  EXPECT_EQ(returned, (std::vector<int>{3, 4, 5, 6, 10, 11}));
  EXPECT_EQ(plain_large, (std::vector<int>{6, 7, 8}));  // all three stand out without the screen
}

}  // namespace
}  // namespace auvdock
