// The sliding window's adaptive per-light noise (EstimatorOptions::adaptive_vision_noise) on
// synthetic runs with white pixel errors: the factors stay near 1 when the configured sigma is
// right, and reach the true variance ratio when the configured sigma is half the true one.
#include <gtest/gtest.h>

#include "auvdock/estimator/sliding_window_estimator.h"
#include "tests/testing/synthetic_vision.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

// Runs the window over a run whose errors are white at 0.3 px, configured as configured_px.
EstimatorStats RunConfiguredAs(double configured_px, uint64_t seed) {
  test::SyntheticRun run = test::MakeSyntheticRun(test::DefaultScenario(), seed, 0.3);
  for (CameraCalibration& camera : run.calibration.cameras) camera.pixel_noise_px = configured_px;
  for (VisionFrame& frame : run.frames) {
    for (MonoLightObservation& obs : frame.mono) obs.sigma_px = configured_px;
  }
  EstimatorOptions options;
  options.adaptive_vision_noise.enabled = true;
  options.window_vision_floor_px = 0.0;  // white errors: the factors alone
  SlidingWindowEstimator estimator(run.calibration, run.dock, options);
  size_t next_imu = 0;
  for (const VisionFrame& frame : run.frames) {
    while (next_imu < run.imu.size() && run.imu[next_imu].t_ns <= frame.t_ns) {
      estimator.AddImu(run.imu[next_imu++]);
    }
    estimator.AddVisionFrame(frame);
  }
  return estimator.stats();
}

TEST(AdaptiveVisionNoise, FactorsStayNearOneWhenTheNoiseIsAsConfigured) {
  const EstimatorStats stats = RunConfiguredAs(0.3, 1);
  ASSERT_FALSE(stats.mono_variance_factor.empty());
  ASSERT_FALSE(stats.stereo_variance_factor.empty());
  for (const auto& [id, f] : stats.mono_variance_factor) EXPECT_NEAR(f, 1.0, 0.25) << id;
  for (const auto& [id, f] : stats.stereo_variance_factor) EXPECT_NEAR(f, 1.0, 0.25) << id;
}

TEST(AdaptiveVisionNoise, FactorsFindErrorsTwiceTheConfiguredSigma) {
  // Configured 0.15 px, true 0.3 px: variance ratio 4.
  const EstimatorStats stats = RunConfiguredAs(0.15, 2);
  ASSERT_FALSE(stats.mono_variance_factor.empty());
  for (const auto& [id, f] : stats.mono_variance_factor) EXPECT_NEAR(f / 4.0, 1.0, 0.3) << id;
  for (const auto& [id, f] : stats.stereo_variance_factor) EXPECT_NEAR(f / 4.0, 1.0, 0.3) << id;
}

TEST(AdaptiveVisionNoise, OffByDefault) {
  test::SyntheticRun run = test::MakeSyntheticRun(test::DefaultScenario(), 3, 0.3);
  SlidingWindowEstimator estimator(run.calibration, run.dock);
  size_t next_imu = 0;
  for (size_t k = 0; k < 60 && k < run.frames.size(); ++k) {
    while (next_imu < run.imu.size() && run.imu[next_imu].t_ns <= run.frames[k].t_ns) {
      estimator.AddImu(run.imu[next_imu++]);
    }
    estimator.AddVisionFrame(run.frames[k]);
  }
  EXPECT_TRUE(estimator.stats().mono_variance_factor.empty());
}

}  // namespace
}  // namespace auvdock
