#include "auvdock/estimator/go_no_go.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace auvdock {
namespace {

using ::testing::HasSubstr;

EstimatorOutput PreciseOutput() {
  EstimatorOutput out;
  out.covariance_ok = true;
  out.covariance = Matrix6d::Identity() * 1e-6;  // 1 mm, 1 mrad
  out.n_mono = 6;
  out.seconds_since_vision = 0.0;
  return out;
}

TEST(GoNoGoTest, PreciseHealthyEstimateIsGo) {
  GoNoGo decide;
  const GoNoGoDecision d = decide.Decide(PreciseOutput());
  EXPECT_TRUE(d.go) << d.reason;
}

TEST(GoNoGoTest, APoseKnownOnlyUpToTheDocksSymmetryIsNoGoWhateverItsCovariance) {
  GoNoGo decide;
  EstimatorOutput out = PreciseOutput();
  out.symmetry_unresolved = true;
  const GoNoGoDecision d = decide.Decide(out);
  EXPECT_FALSE(d.go);
  EXPECT_THAT(d.reason, HasSubstr("up to the dock's symmetry"));
  EXPECT_EQ(d.reason.find(','), std::string::npos);  // a CSV field
}

TEST(GoNoGoTest, LateralThreeSigmaUsesTheMajorAxisOfTheHorizontalCovariance) {
  GoNoGoOptions options;
  options.allowed_lateral_error_m = 0.10;
  GoNoGo decide(options);
  EstimatorOutput out = PreciseOutput();
  // sigma_x = sigma_y = 0.02 m but fully correlated: the major axis is 0.02 sqrt(2) = 0.028 m,
  // 3 sigma = 0.085 m: GO; at 0.025 m per axis it is 0.106 m: NO-GO.
  out.covariance.topLeftCorner<2, 2>() << 4e-4, 4e-4, 4e-4, 4e-4;
  EXPECT_TRUE(decide.Decide(out).go);
  out.covariance.topLeftCorner<2, 2>() << 6.25e-4, 6.25e-4, 6.25e-4, 6.25e-4;
  const GoNoGoDecision d = decide.Decide(out);
  EXPECT_FALSE(d.go);
  EXPECT_THAT(d.reason, HasSubstr("3-sigma lateral 0.106 m"));
}

TEST(GoNoGoTest, YawUncertaintyAboveTheLimitIsNoGo) {
  GoNoGo decide;
  EstimatorOutput out = PreciseOutput();
  out.covariance(5, 5) = 0.02 * 0.02;  // 3 sigma = 0.06 rad > 0.05
  const GoNoGoDecision d = decide.Decide(out);
  EXPECT_FALSE(d.go);
  EXPECT_THAT(d.reason, HasSubstr("yaw"));
}

TEST(GoNoGoTest, StaleVisionMissingCovarianceAndNoEstimateAreNoGo) {
  GoNoGo decide;
  EstimatorOutput stale = PreciseOutput();
  stale.seconds_since_vision = 2.0;
  EXPECT_THAT(decide.Decide(stale).reason, HasSubstr("no vision for 2.00 s"));
  EstimatorOutput never = PreciseOutput();
  never.seconds_since_vision = -1.0;
  EXPECT_FALSE(decide.Decide(never).go);
  EstimatorOutput singular = PreciseOutput();
  singular.covariance_ok = false;
  EXPECT_THAT(decide.Decide(singular).reason, HasSubstr("covariance unavailable"));
  EXPECT_FALSE(decide.NoEstimate("reset").go);
}

// With the DVL fused, stale vision alone is not NO-GO: the covariance decides, up to
// max_aided_vision_age_s without lights; a DVL sample too old does not count.
TEST(GoNoGoTest, RecentDvlLetsVisionBeOlderAndTheCovarianceDecide) {
  GoNoGo decide;
  EstimatorOutput aided = PreciseOutput();
  aided.seconds_since_vision = 4.0;
  aided.seconds_since_dvl = 0.2;
  const GoNoGoDecision go = decide.Decide(aided);
  EXPECT_TRUE(go.go) << go.reason;
  EXPECT_THAT(go.reason, HasSubstr("DVL-aided: no vision for 4.00 s"));
  aided.covariance.topLeftCorner<2, 2>() *= 1e4;  // 10 cm 1-sigma: the covariance says no
  EXPECT_THAT(decide.Decide(aided).reason, HasSubstr("3-sigma lateral"));
  EstimatorOutput old_dvl = PreciseOutput();
  old_dvl.seconds_since_vision = 4.0;
  old_dvl.seconds_since_dvl = 2.0;
  EXPECT_THAT(decide.Decide(old_dvl).reason, HasSubstr("without the DVL"));
  EstimatorOutput too_long = PreciseOutput();
  too_long.seconds_since_vision = 12.0;
  too_long.seconds_since_dvl = 0.1;
  EXPECT_THAT(decide.Decide(too_long).reason, HasSubstr("limit 10.00 s with the DVL"));
}

TEST(GoNoGoTest, ManyGatedResidualsInRecentFramesAreNoGo) {
  GoNoGoOptions options;
  options.max_gating_rate = 0.3;
  options.gating_window_frames = 4;
  GoNoGo decide(options);
  EstimatorOutput out = PreciseOutput();
  out.n_mono = 4;
  out.n_gated = 2;  // 2 of 6 = 0.33 per frame
  const GoNoGoDecision d = decide.Decide(out);
  EXPECT_FALSE(d.go);
  EXPECT_THAT(d.reason, HasSubstr("gating rate 0.33"));
  // Four clean frames push the gated one out of the window.
  for (int i = 0; i < 3; ++i) decide.Decide(PreciseOutput());
  EXPECT_TRUE(decide.Decide(PreciseOutput()).go);
}

// A depth sensor the gate keeps rejecting disagrees with the estimate: NO-GO once enough samples
// came, GO again once the rejections leave the window; a single rejected sample among few is not
// enough to judge.
TEST(GoNoGoTest, ADepthThatTheGateKeepsRejectingIsNoGo) {
  GoNoGoOptions options;
  options.gating_window_frames = 4;
  options.min_depth_samples = 3;
  GoNoGo decide(options);
  EstimatorOutput out = PreciseOutput();
  out.n_depth = 1;
  out.n_depth_gated = 1;
  EXPECT_TRUE(decide.Decide(out).go);  // 1 sample: too few to judge
  out.n_depth = 2;
  out.n_depth_gated = 1;
  const GoNoGoDecision d = decide.Decide(out);  // 2 of 3 gated
  EXPECT_FALSE(d.go);
  EXPECT_THAT(d.reason, HasSubstr("the depth disagrees: 2 of 3 samples gated"));
  EstimatorOutput clean = PreciseOutput();
  clean.n_depth = 1;
  for (int i = 0; i < 3; ++i) decide.Decide(clean);
  EXPECT_TRUE(decide.Decide(clean).go);  // the gated ones have left the window
}

TEST(GoNoGoTest, RejectsNonPositiveThresholds) {
  GoNoGoOptions options;
  options.allowed_lateral_error_m = 0.0;
  EXPECT_THROW(GoNoGo{options}, std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
