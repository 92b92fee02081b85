#include "auvdock/estimator/usbl_rate_test.h"

#include <cmath>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

AcousticFix Fix(double t_s, double x, double sigma = 0.1) {
  AcousticFix f;
  f.t_ns = static_cast<int64_t>(t_s * 1e9);
  f.p_D = Eigen::Vector3d(x, 1.0, -4.0);
  f.sigma_m = sigma;
  return f;
}

// A vehicle at 0.5 m/s: every fix passes and, kept by the gate, becomes the reference; a 2 m
// jump one second later fails (1.5 m/s allowed, 3 sigma) with its reason; the next good fix
// passes against the last good reference.
TEST(UsblRateTest, AJumpFasterThanTheVehicleFailsAgainstAConfirmedReference) {
  UsblRateTest test;
  EXPECT_TRUE(test.Check(Fix(0.0, -8.0)).pass);  // no reference: no opinion
  test.Confirm(Fix(0.0, -8.0).t_ns);
  const UsblRateVerdict good = test.Check(Fix(1.0, -7.5));
  EXPECT_TRUE(good.pass);
  // (0.5 - 1.5) / (0.1 sqrt 2)
  EXPECT_NEAR(good.excess, -1.0 / (0.1 * std::sqrt(2.0)), 1e-9);
  test.Confirm(Fix(1.0, -7.5).t_ns);
  const UsblRateVerdict jump = test.Check(Fix(2.0, -5.0));
  EXPECT_FALSE(jump.pass);
  EXPECT_NEAR(jump.excess, (2.5 - 1.5) / (0.1 * std::sqrt(2.0)), 1e-9);
  EXPECT_NE(jump.reason.find("rate test"), std::string::npos);
  EXPECT_TRUE(test.Check(Fix(3.0, -6.5)).pass);  // 1.0 m in 2 s from the reference
}

// A survey AUV at 2.2 m/s: against the docking bound (1.5 m/s) its good fixes fail; once the
// estimator gives the test the vehicle's speed the bound is that speed plus the margin
// (0.5 m/s), and they pass, while a jump faster than that still fails. A slower estimate never
// lowers the bound below max_speed_mps.
TEST(UsblRateTest, TheSpeedBoundFollowsTheEstimatedSpeed) {
  UsblRateTest test;
  EXPECT_TRUE(test.Check(Fix(0.0, -80.0)).pass);
  test.Confirm(Fix(0.0, -80.0).t_ns);
  EXPECT_TRUE(test.Check(Fix(1.0, -78.5)).pass);  // 1.5 m/s: the reference is confirmed
  test.Confirm(Fix(1.0, -78.5).t_ns);
  EXPECT_FALSE(test.Check(Fix(2.0, -76.3)).pass);  // 2.2 m in 1 s against 1.5 m/s + 3 sigma
  test.SetEstimatedSpeed(2.2);
  EXPECT_DOUBLE_EQ(test.speed_bound_mps(), 2.7);
  const UsblRateVerdict good = test.Check(Fix(2.0, -76.3));
  EXPECT_TRUE(good.pass);
  EXPECT_NEAR(good.excess, (2.2 - 2.7) / (0.1 * std::sqrt(2.0)), 1e-9);
  test.Confirm(Fix(2.0, -76.3).t_ns);
  const UsblRateVerdict jump = test.Check(Fix(3.0, -72.8));  // 3.5 m in 1 s
  EXPECT_FALSE(jump.pass);
  EXPECT_NE(jump.reason.find("at most 2.70 m/s"), std::string::npos) << jump.reason;
  test.SetEstimatedSpeed(0.2);
  EXPECT_DOUBLE_EQ(test.speed_bound_mps(), 1.5);
  test.SetEstimatedSpeed(std::nan(""));
  EXPECT_DOUBLE_EQ(test.speed_bound_mps(), 1.5);
}

// An outlier as the first fix: the test has no opinion on the next one (the reference never
// passed itself), so a good fix is not rejected against it and the test does not lock.
TEST(UsblRateTest, AnOutlierAsTheFirstFixDoesNotLockTheTest) {
  UsblRateTest test;
  EXPECT_TRUE(test.Check(Fix(0.0, -3.0)).pass);  // the outlier, kept by a gate with no opinion
  test.Confirm(Fix(0.0, -3.0).t_ns);
  EXPECT_TRUE(test.Check(Fix(1.0, -7.5)).pass);  // 4.5 m away: no opinion
  test.Confirm(Fix(1.0, -7.5).t_ns);
  EXPECT_TRUE(test.Check(Fix(2.0, -7.0)).pass);
  test.Confirm(Fix(2.0, -7.0).t_ns);
  EXPECT_FALSE(test.Check(Fix(3.0, -3.0)).pass);  // now against a tested reference
}

TEST(UsblRateTest, AnOldReferenceIsDroppedAndAnUnconfirmedCandidateIsNot) {
  UsblRateTest test;
  test.Check(Fix(0.0, -8.0));
  test.Confirm(Fix(0.0, -8.0).t_ns);
  test.Check(Fix(1.0, -7.5));
  test.Confirm(Fix(1.0, -7.5).t_ns);
  // Not confirmed (the gate rejected it): the reference stays at t = 1 s.
  EXPECT_TRUE(test.Check(Fix(2.0, -7.0)).pass);
  EXPECT_FALSE(test.Check(Fix(3.0, -3.0)).pass);  // 4.5 m in 2 s from t = 1 s
  // 20 s later the reference is too old: no opinion.
  EXPECT_TRUE(test.Check(Fix(21.0, 5.0)).pass);
  UsblRateTestOptions off;
  off.enabled = false;
  UsblRateTest disabled(off);
  disabled.Check(Fix(0.0, -8.0));
  disabled.Confirm(0);
  EXPECT_TRUE(disabled.Check(Fix(1.0, 10.0)).pass);
}

SblRange Range(double t_s, double range_m, double sigma = 0.05) {
  SblRange r;
  r.t_ns = static_cast<int64_t>(t_s * 1e9);
  r.transducer = 2;
  r.range_m = range_m;
  r.sigma_m = sigma;
  return r;
}

// One transducer's slant ranges at 0.5 m/s of closing speed, then a multipath reply 2.4 m long
// (1.9 m of change in 1 s, 1.5 m/s allowed): it fails with its own reason, the next direct
// reply passes against the last good range.
TEST(UsblRateTest, ARangeThatGrowsFasterThanTheVehicleFails) {
  UsblRateTest test;
  EXPECT_TRUE(test.Check(Range(0.0, 9.0)).pass);
  test.Confirm(Range(0.0, 9.0).t_ns);
  const UsblRateVerdict good = test.Check(Range(1.0, 8.5));
  EXPECT_TRUE(good.pass);
  EXPECT_NEAR(good.excess, (0.5 - 1.5) / (0.05 * std::sqrt(2.0)), 1e-9);
  test.Confirm(Range(1.0, 8.5).t_ns);
  const UsblRateVerdict multipath = test.Check(Range(2.0, 8.0 + 2.4));
  EXPECT_FALSE(multipath.pass);
  EXPECT_NE(multipath.reason.find("last good range"), std::string::npos) << multipath.reason;
  EXPECT_TRUE(test.Check(Range(3.0, 7.5)).pass);  // 1.0 m in 2 s from the reference
}

}  // namespace
}  // namespace auvdock
