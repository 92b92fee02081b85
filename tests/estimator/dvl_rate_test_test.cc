#include "auvdock/estimator/dvl_rate_test.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

const Eigen::Vector3d kGravity_D(0.0, 0.0, 9.81);

// A level body gliding at 0.5 m/s along x (D = B axes), its IMU at 200 Hz for 20 s, and its DVL
// (mounted 45 degrees about z, 0.3 m ahead) at 5 Hz with 1 cm/s noise.
class DvlRateTestTest : public ::testing::Test {
 protected:
  DvlRateTestTest() : imu_(ImuCalibration(), 0.1) {
    calibration_.sigma_mps = 0.01;
    calibration_.T_B_S = Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ())),
                               Eigen::Vector3d(0.3, 0.0, 0.0));
    for (int k = 0; k <= 4000; ++k) {
      ImuSample s;
      s.t_ns = k * 5000000LL;
      s.accel = -kGravity_D;  // specific force of a body at rest or in uniform motion, level
      imu_.Add(s);
    }
  }

  DvlMeasurement Sample(int k, const Eigen::Vector3d& error = Eigen::Vector3d::Zero()) {
    DvlMeasurement m;
    m.t_ns = k * 200000000LL;
    std::normal_distribution<double> n(0.0, calibration_.sigma_mps);
    m.v_S = calibration_.T_B_S.q.conjugate() * Eigen::Vector3d(0.5, 0.0, 0.0) +
            Eigen::Vector3d(n(rng_), n(rng_), n(rng_)) + error;
    return m;
  }

  DvlRateVerdict Check(DvlRateTest* test, const DvlMeasurement& m) {
    return test->Check(m, imu_, ImuBias(), Eigen::Quaterniond::Identity(), kGravity_D);
  }

  DvlCalibration calibration_;
  ImuBuffer imu_;
  std::mt19937_64 rng_{7};
};

TEST_F(DvlRateTestTest, CleanSamplesPassAfterTheFirstAndSpikesFail) {
  DvlRateTest test(calibration_, DvlRateTestOptions());
  const DvlRateVerdict first = Check(&test, Sample(0));
  EXPECT_FALSE(first.pass);
  EXPECT_TRUE(first.held);  // nothing to test it against yet: the next sample decides
  EXPECT_TRUE(std::isnan(first.statistic));
  int passed = 0;
  for (int k = 1; k < 50; ++k) {
    const bool spike = k % 10 == 5;
    const DvlRateVerdict v = Check(&test, Sample(k, spike ? Eigen::Vector3d(0.0, 0.3, 0.0)
                                                          : Eigen::Vector3d::Zero()));
    if (spike) {
      EXPECT_FALSE(v.pass) << k;
      EXPECT_GT(v.statistic, 100.0) << k;
    } else {
      passed += v.pass;
      if (v.pass) test.Confirm(Sample(k).t_ns);
      if (k == 1) {  // agrees with the first, which is released to the estimator
        ASSERT_TRUE(v.released.has_value());
        EXPECT_EQ(v.released->t_ns, Sample(0).t_ns);
      }
    }
  }
  EXPECT_GE(passed, 43);  // of 45 clean samples (p = 0.999 each)
}

// A long small bias (0.2 m/s for 2 s) fails all along: the reference stays the last good sample.
TEST_F(DvlRateTestTest, ALongSmallBiasFailsWhileTheReferenceIsYoung) {
  DvlRateTest test(calibration_, DvlRateTestOptions());
  for (int k = 0; k < 10; ++k) {
    if (Check(&test, Sample(k)).pass) test.Confirm(Sample(k).t_ns);
  }
  for (int k = 10; k < 20; ++k) {
    const DvlRateVerdict v = Check(&test, Sample(k, Eigen::Vector3d(0.2, 0.0, 0.0)));
    EXPECT_FALSE(v.pass) << k << " " << v.statistic;
  }
  EXPECT_TRUE(Check(&test, Sample(20)).pass);  // back to normal: the reference held
}

// A spike as the very first sample does not lock the test: the next clean sample disagrees
// with it, so the held spike is rejected and the clean one held in its place; the one after
// agrees with it, passes and releases it, and once kept is the reference.
TEST_F(DvlRateTestTest, ASpikeFirstDoesNotLockTheTest) {
  DvlRateTest test(calibration_, DvlRateTestOptions());
  EXPECT_TRUE(Check(&test, Sample(0, Eigen::Vector3d(0.5, 0.0, 0.0))).held);
  const DvlRateVerdict second = Check(&test, Sample(1));
  EXPECT_FALSE(second.pass);
  EXPECT_TRUE(second.held);
  ASSERT_TRUE(second.dropped.has_value());
  EXPECT_EQ(second.dropped->t_ns, Sample(0).t_ns);
  EXPECT_FALSE(second.released.has_value());
  for (int k = 2; k < 10; ++k) {
    const DvlMeasurement m = Sample(k);
    const DvlRateVerdict v = Check(&test, m);
    EXPECT_TRUE(v.pass) << k;
    EXPECT_EQ(v.released.has_value(), k == 2) << k;
    test.Confirm(m.t_ns);
  }
  EXPECT_FALSE(Check(&test, Sample(10, Eigen::Vector3d(0.0, 0.0, 0.3))).pass);
}

// A spike right after the first sample is rejected, not passed to the gate (which at a start
// has no other velocity to hold it against and would keep it as the reference that rejects
// every clean sample after it); two clean samples later the test passes clean samples again.
TEST_F(DvlRateTestTest, ASpikeSecondIsNotLetThrough) {
  DvlRateTest test(calibration_, DvlRateTestOptions());
  EXPECT_FALSE(Check(&test, Sample(0)).pass);
  const DvlMeasurement spike = Sample(1, Eigen::Vector3d(-0.17, 0.28, -0.17));
  const DvlRateVerdict at_spike = Check(&test, spike);
  EXPECT_FALSE(at_spike.pass);
  EXPECT_TRUE(at_spike.dropped.has_value());  // the first: of two that disagree, either may be bad
  test.Confirm(spike.t_ns);  // a gate's word cannot make it the reference: it was not passed
  const DvlRateVerdict after = Check(&test, Sample(2));
  EXPECT_FALSE(after.pass);  // disagrees with the untested spike
  ASSERT_TRUE(after.dropped.has_value());
  EXPECT_EQ(after.dropped->t_ns, spike.t_ns);
  int passed = 0;
  for (int k = 3; k < 20; ++k) {
    const DvlMeasurement m = Sample(k);
    const DvlRateVerdict v = Check(&test, m);
    if (v.released) {
      EXPECT_NE(v.released->t_ns, spike.t_ns);
    }
    if (v.pass) {
      ++passed;
      test.Confirm(m.t_ns);
    }
  }
  EXPECT_GE(passed, 16);
}

// An unconfirmed candidate (the gate did not keep it) is not the next reference; a reference
// older than max_reference_age_s is dropped, so a sensor that really changed is heard again.
TEST_F(DvlRateTestTest, OnlyConfirmedCandidatesBecomeTheReferenceAndOldOnesExpire) {
  DvlRateTestOptions options;
  options.max_reference_age_s = 1.0;
  DvlRateTest test(calibration_, options);
  Check(&test, Sample(0));
  ASSERT_TRUE(Check(&test, Sample(1)).pass);
  test.Confirm(Sample(1).t_ns);
  const Eigen::Vector3d changed(0.0, 0.25, 0.0);
  for (int k = 2; k < 7; ++k) {
    EXPECT_FALSE(Check(&test, Sample(k, changed)).pass) << k;  // within 1 s of the reference
  }
  const DvlRateVerdict expired = Check(&test, Sample(7, changed));  // 1.2 s after it
  EXPECT_FALSE(expired.pass);
  EXPECT_TRUE(std::isnan(expired.statistic));
  EXPECT_TRUE(Check(&test, Sample(8, changed)).pass);  // the changed sensor, consistent again
}

// The first clean sample after a fault that outlasted the reference is held, not rejected, and
// released by the next; a held sample that nothing comes to test expires.
TEST_F(DvlRateTestTest, TheFirstCleanSampleAfterALongFaultIsHeldNotRejected) {
  DvlRateTestOptions options;
  options.max_reference_age_s = 1.0;
  DvlRateTest test(calibration_, options);
  for (int k = 0; k < 5; ++k) {
    if (Check(&test, Sample(k)).pass) test.Confirm(Sample(k).t_ns);
  }
  const Eigen::Vector3d bias(0.3, 0.0, 0.0);
  for (int k = 5; k < 12; ++k) Check(&test, Sample(k, bias));  // the gate keeps none of them
  const DvlRateVerdict clean = Check(&test, Sample(12));
  EXPECT_FALSE(clean.pass);
  EXPECT_TRUE(clean.held) << clean.reason;
  const DvlRateVerdict next = Check(&test, Sample(13));
  EXPECT_TRUE(next.pass);
  ASSERT_TRUE(next.released.has_value());
  EXPECT_EQ(next.released->t_ns, Sample(12).t_ns);

  DvlRateTest lone(calibration_, options);
  ASSERT_TRUE(Check(&lone, Sample(0)).held);
  EXPECT_FALSE(lone.ExpireHeld(Sample(5).t_ns).has_value());  // 1.0 s: not yet
  const std::optional<DvlMeasurement> expired = lone.ExpireHeld(Sample(6).t_ns);
  ASSERT_TRUE(expired.has_value());
  EXPECT_EQ(expired->t_ns, Sample(0).t_ns);
  EXPECT_FALSE(lone.ExpireHeld(Sample(20).t_ns).has_value());
}

// Right after a start the state's tilt is known only to ~0.03 rad: the IMU's prediction then
// carries g sin(0.03) = 0.29 m/s^2 of error, 0.06 m/s over a DVL period. Taken as exact, clean
// samples sit at the gate (chi-square ~16 against 16.27) and most fail; with the state's
// uncertainty (SetStateUncertainty) they pass at ~1, and a 0.3 m/s spike still fails.
TEST_F(DvlRateTestTest, TheStatesUncertaintyWidensThePrediction) {
  const Eigen::Quaterniond tilted(Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX()));
  for (const bool with_uncertainty : {false, true}) {
    DvlRateTest test(calibration_, DvlRateTestOptions());
    if (with_uncertainty) test.SetStateUncertainty(9.81 * 0.03);
    const auto check = [&](const DvlMeasurement& m) {
      return test.Check(m, imu_, ImuBias(), tilted, kGravity_D);
    };
    check(Sample(0));  // held: no reference yet
    int passed = 0;
    double statistic_sum = 0.0;
    for (int k = 1; k < 10; ++k) {
      const DvlMeasurement m = Sample(k);
      const DvlRateVerdict v = check(m);
      statistic_sum += v.statistic;
      if (v.pass) {
        ++passed;
        test.Confirm(m.t_ns);
      }
    }
    if (with_uncertainty) {
      EXPECT_EQ(passed, 9);
      EXPECT_LT(statistic_sum / 9.0, 3.0);
    } else {
      EXPECT_LE(passed, 2);
      EXPECT_GT(statistic_sum / 9.0, 10.0);
    }
    if (with_uncertainty) {
      EXPECT_FALSE(check(Sample(10, Eigen::Vector3d(0.0, 0.3, 0.0))).pass);
    }
  }
}

}  // namespace
}  // namespace auvdock
