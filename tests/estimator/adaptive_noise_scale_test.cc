// AdaptiveNoiseScale: the variance factor converges to the true one from residuals whitened by
// the factor in use, stays within its bounds, and does nothing when disabled.
#include "auvdock/estimator/adaptive_noise_scale.h"

#include <random>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

// Feeds frames of 6 pixel pairs whose true sigma is true_factor^0.5 times the configured one,
// after a solve that absorbed `leverage` of each pair's 2 degrees of freedom.
double Converge(double true_factor, const AdaptiveNoiseOptions& options, int frames = 2000) {
  AdaptiveNoiseScale scale(options);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double leverage = 0.3;
  for (int f = 0; f < frames; ++f) {
    for (int k = 0; k < 6; ++k) {
      // A residual of true variance true_factor (configured units) times (1 - leverage / 2)
      // per coordinate, whitened by the factor in use.
      double squared = 0.0;
      for (int c = 0; c < 2; ++c) {
        const double r = std::sqrt(true_factor * (1.0 - leverage / 2.0)) * unit(rng);
        squared += r * r / scale.factor();
      }
      scale.Update(squared, 2.0 - leverage);
    }
  }
  return scale.factor();
}

TEST(AdaptiveNoiseScale, ConvergesToTheTrueFactor) {
  const AdaptiveNoiseOptions options;
  EXPECT_NEAR(Converge(1.0, options), 1.0, 0.15);
  EXPECT_NEAR(Converge(9.0, options) / 9.0, 1.0, 0.15);   // errors 3x the configured sigma
  EXPECT_NEAR(Converge(0.36, options) / 0.36, 1.0, 0.15);  // better than configured
}

TEST(AdaptiveNoiseScale, StaysWithinItsBounds) {
  const AdaptiveNoiseOptions options;
  EXPECT_DOUBLE_EQ(Converge(100.0, options), options.max_factor);
  EXPECT_DOUBLE_EQ(Converge(0.01, options), options.min_factor);
}

TEST(AdaptiveNoiseScale, OneBadFrameMovesItLittle) {
  AdaptiveNoiseScale scale;
  for (int i = 0; i < 200; ++i) scale.Update(2.0, 2.0);  // exactly as configured
  ASSERT_NEAR(scale.factor(), 1.0, 1e-9);
  scale.Update(2.0 * 100.0, 2.0);  // one pair 10 sigma off
  EXPECT_LT(scale.factor(), 2.1);
}

TEST(AdaptiveNoiseScale, WaitsForEnoughDataAndCanBeOff) {
  AdaptiveNoiseScale scale;
  scale.Update(50.0, 2.0);  // 2 of the 20 degrees of freedom needed
  EXPECT_EQ(scale.factor(), 1.0);
  AdaptiveNoiseOptions off;
  off.enabled = false;
  EXPECT_EQ(Converge(9.0, off, 100), 1.0);
  scale.Update(-1.0, 2.0);  // ignored: not a squared residual
  scale.Update(1.0, 0.0);   // ignored: no redundancy
  EXPECT_EQ(scale.redundancy_seen(), 2.0);
}

}  // namespace
}  // namespace auvdock
