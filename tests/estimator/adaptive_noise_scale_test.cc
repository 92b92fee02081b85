// AdaptiveNoiseScale: the variance factor converges to the true one from residuals whitened by
// the factor in use, stays within its bounds, and does nothing when disabled.
#include "auvdock/estimator/adaptive_noise_scale.h"

#include <algorithm>
#include <cmath>
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

// A sensor whose error is as large as configured but correlated between samples (AR(1),
// rho 0.8, as a real DVL's over seconds): the difference of consecutive samples has the variance
// 2 (1 - rho) instead of 2, so a factor from differences says 0.2. The state-free options keep
// the configured noise; the default ones would believe the sensor 4x more than they should.
TEST(AdaptiveNoiseScale, DifferencesOfACorrelatedErrorDoNotNarrowTheStateFreeFactor) {
  const double rho = 0.8;
  for (const bool state_free : {false, true}) {
    AdaptiveNoiseScale scale(state_free ? kStateFreeNoiseOptions : AdaptiveNoiseOptions{});
    std::mt19937_64 rng(5);
    std::normal_distribution<double> unit(0.0, 1.0);
    double error = unit(rng);
    for (int k = 0; k < 5000; ++k) {
      const double next = rho * error + std::sqrt(1.0 - rho * rho) * unit(rng);
      const double difference = next - error;
      error = next;
      scale.Update(difference * difference / (2.0 * scale.factor()), 1.0);
    }
    if (state_free) {
      EXPECT_DOUBLE_EQ(scale.factor(), 1.0);
    } else {
      EXPECT_LT(scale.factor(), 0.3);
    }
  }
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

TEST(ChiSquareCdf, KnownValues) {
  // Tabulated quantiles (p = 0.95, 0.999) and the medians.
  EXPECT_NEAR(ChiSquareCdf(1, 3.841), 0.95, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(1, 10.83), 0.999, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(2, 5.991), 0.95, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(3, 16.27), 0.999, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(3, 2.366), 0.5, 1e-3);
  EXPECT_NEAR(ChiSquareCdf(6, 12.59), 0.95, 1e-4);
  EXPECT_NEAR(ChiSquareCdf(7, 14.07), 0.95, 1e-4);
  EXPECT_EQ(ChiSquareCdf(3, 0.0), 0.0);
  EXPECT_EQ(ChiSquareCdf(3, -1.0), 0.0);
  EXPECT_NEAR(ChiSquareCdf(1, 1e6), 1.0, 1e-12);
}

// Statistics lambda chi2_dof (whitened by the factor in use), a share `outliers` of them far
// out (a multipath reply), fed to UpdateCensored with the cutoff c.
double ConvergeCensored(double true_factor, int dof, double outliers, double cutoff) {
  AdaptiveNoiseScale scale(AdaptiveNoiseOptions{true, 100.0});
  std::mt19937_64 rng(5);
  std::chi_squared_distribution<double> chi2(dof);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const double statistic =
        u(rng) < outliers ? 1e4 : true_factor * chi2(rng) / scale.factor();
    scale.UpdateCensored(statistic, dof, cutoff);
  }
  return scale.factor();
}

TEST(AdaptiveNoiseScale, CensoredUpdateIgnoresOutliersAndKeepsTheTrueFactor) {
  for (const int dof : {1, 3}) {
    const double cutoff = dof == 1 ? 10.83 : 16.27;
    EXPECT_NEAR(ConvergeCensored(1.0, dof, 0.0, cutoff), 1.0, 0.15) << dof;
    EXPECT_NEAR(ConvergeCensored(1.0, dof, 0.06, cutoff), 1.0, 0.15) << dof;
    EXPECT_NEAR(ConvergeCensored(9.0, dof, 0.06, cutoff) / 9.0, 1.0, 0.15) << dof;
    EXPECT_NEAR(ConvergeCensored(0.36, dof, 0.0, cutoff) / 0.36, 1.0, 0.15) << dof;
    // A cutoff at p = 0.95 leaves 5 % of the good statistics out, and the truncated mean
    // corrects for it (kept statistics average 0.76 of dof 1's mean, 0.88 of dof 3's).
    const double cutoff95 = dof == 1 ? 3.841 : 7.815;
    EXPECT_NEAR(ConvergeCensored(1.0, dof, 0.0, cutoff95), 1.0, 0.15) << dof;
    EXPECT_NEAR(ConvergeCensored(4.0, dof, 0.0, cutoff95) / 4.0, 1.0, 0.15) << dof;
  }
  // Clipping at the cutoff instead (what UpdateCensored replaces) is biased by the outliers.
  AdaptiveNoiseScale clipped(AdaptiveNoiseOptions{true, 100.0});
  std::mt19937_64 rng(5);
  std::chi_squared_distribution<double> chi2(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const double statistic = u(rng) < 0.06 ? 1e4 : chi2(rng) / clipped.factor();
    clipped.Update(std::min(statistic, 10.83), 1.0);
  }
  EXPECT_GT(clipped.factor(), 1.4);
}

TEST(AdaptiveNoiseScale, CensoredUpdateCountsWhatItLeavesOut) {
  AdaptiveNoiseScale scale;
  scale.UpdateCensored(20.0, 1, 10.83);
  scale.UpdateCensored(1.0, 1, 10.83);
  scale.UpdateCensored(-1.0, 1, 10.83);  // ignored: not a statistic
  EXPECT_EQ(scale.censored(), 1);
  EXPECT_EQ(scale.redundancy_seen(), 1.0);
  scale.UpdateCensored(20.0, 1, 0.0);  // no cutoff (a sensor with its gate off): counted
  EXPECT_EQ(scale.censored(), 1);
  EXPECT_EQ(scale.redundancy_seen(), 2.0);
}

}  // namespace
}  // namespace auvdock
