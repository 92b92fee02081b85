#include "auvdock/estimator/acoustic_initializer.h"

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "tests/testing/synthetic_vision.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

// The long approach's first 20 s (no light is seen there).
test::SyntheticRun MakeFarApproach() {
  Scenario scenario = test::LongApproachScenario(20.0);
  scenario.dvl_faults.gross_error_probability = 0.0;
  return test::MakeSyntheticRun(scenario, 3);
}

// The heading of R_D_B about the dock's gravity (z in D), wrapped to (-pi, pi].
double HeadingError(const Pose3& estimate, const Pose3& truth) {
  return LogSO3((estimate.q * truth.q.conjugate()).toRotationMatrix()).z();
}

const GroundTruthState& StateAt(const test::SyntheticRun& run, int64_t t_ns) {
  size_t i = 0;
  while (i + 1 < run.states.size() && run.states[i + 1].t_ns <= t_ns) ++i;
  return run.states[i];
}

struct Fed {
  size_t imu = 0, dvl = 0, fix = 0;
};

// Everything up to t_ns into the buffer and the initializer.
void FeedUpTo(const test::SyntheticRun& run, const std::vector<AcousticFix>& fixes, int64_t t_ns,
              ImuBuffer* imu, AcousticInitializer* init, Fed* fed) {
  while (fed->imu < run.imu.size() && run.imu[fed->imu].t_ns <= t_ns) imu->Add(run.imu[fed->imu++]);
  while (fed->dvl < run.dvl.size() && run.dvl[fed->dvl].t_ns <= t_ns) init->AddDvl(run.dvl[fed->dvl++]);
  while (fed->fix < fixes.size() && fixes[fed->fix].t_ns <= t_ns) init->AddFix(fixes[fed->fix++]);
}

TEST(AcousticInitializerTest, GivesTheHeadingAndPositionWithinTheirSigmasOnceTheVehicleHasMoved) {
  const test::SyntheticRun run = MakeFarApproach();
  const std::vector<AcousticFix> fixes = test::MakeAcousticFixes(run, 11);
  ImuBuffer imu(*run.calibration.imu, 0.1);
  AcousticInitializer init(run.calibration, run.dock);
  Fed fed;
  std::string why;
  int first = -1;
  int checked = 0;
  for (size_t k = 0; k < run.frames.size(); ++k) {
    const int64_t t = run.frames[k].t_ns;
    FeedUpTo(run, fixes, t, &imu, &init, &fed);
    const std::optional<InitialState> state = init.Solve(imu, t, &why);
    if (!state) {
      EXPECT_EQ(first, -1) << "a state, then none, at frame " << k << ": " << why;
      EXPECT_THAT(why, HasSubstr("acoustic start: "));
      continue;
    }
    if (first < 0) first = static_cast<int>(k);
    const Pose3& truth = run.truth[k].T_D_B;
    const double heading_error = HeadingError(state->T_D_B, truth);
    EXPECT_LE(std::abs(heading_error), 3.0 * state->heading_sigma_rad) << k;
    EXPECT_LE(state->heading_sigma_rad, 0.11);
    // Position: each axis within 3 sigma of its covariance.
    const Eigen::Vector3d dp = state->T_D_B.p - truth.p;
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(dp(i)), 3.0 * std::sqrt(state->pose_covariance(i, i)) + 1e-3)
          << k << " axis " << i;
    }
    // Tilt from the accelerometer, within 3 of its sigma.
    const Eigen::Vector3d dtheta =
        LogSO3((state->T_D_B.q * truth.q.conjugate()).toRotationMatrix());
    EXPECT_LE(dtheta.head<2>().norm(), 3.0 * AcousticInitOptions().tilt_sigma_rad) << k;
    // Velocity, within 3 sigma of its covariance per axis.
    const GroundTruthState& true_state = StateAt(run, t);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(state->v_D(i) - true_state.v_D(i)),
                3.0 * std::sqrt(state->velocity_covariance(i, i)))
          << k << " axis " << i;
    }
    ++checked;
  }
  ASSERT_GE(first, 0) << why;
  // A fix a second from 0.3 s: the fourth fix and a few metres of travel.
  EXPECT_LE(run.frames[first].t_ns - run.frames.front().t_ns, 8'000'000'000);
  EXPECT_GT(checked, 100);
}

TEST(AcousticInitializerTest, SaysWhyBeforeEnoughFixesAndLeavesAMultipathFixOut) {
  const test::SyntheticRun run = MakeFarApproach();
  std::vector<AcousticFix> fixes = test::MakeAcousticFixes(run, 12);
  fixes[2].p_D.y() += 3.0;  // a multipath fix 3 m off
  ImuBuffer imu(*run.calibration.imu, 0.1);
  AcousticInitializer init(run.calibration, run.dock);
  Fed fed;
  std::string why;
  // After 2 fixes: not enough.
  const int64_t t_two = fixes[1].t_ns + 50'000'000;
  FeedUpTo(run, fixes, t_two, &imu, &init, &fed);
  EXPECT_FALSE(init.Solve(imu, t_two, &why).has_value());
  EXPECT_THAT(why, HasSubstr("fixes on the DVL's path"));
  EXPECT_FALSE(init.has_new_data());
  // After 12 s: a state, without the multipath fix.
  const int64_t t_end = fixes[11].t_ns + 50'000'000;
  FeedUpTo(run, fixes, t_end, &imu, &init, &fed);
  EXPECT_TRUE(init.has_new_data());
  const std::optional<InitialState> state = init.Solve(imu, t_end, &why);
  ASSERT_TRUE(state.has_value()) << why;
  EXPECT_EQ(state->fixes_rejected, 1);
  EXPECT_EQ(state->fixes_used, 11);
  size_t k = 0;
  while (run.truth[k].t_ns < t_end) ++k;
  EXPECT_LT((state->T_D_B.p - run.truth[k - 1].T_D_B.p).head<2>().norm(), 0.3);
}

TEST(AcousticInitializerTest, NeedsBothSensorsAndForgetsThePathBeforeADvlGap) {
  test::SyntheticRun run = MakeFarApproach();
  const std::vector<AcousticFix> fixes = test::MakeAcousticFixes(run, 13);
  {
    Calibration no_dvl = run.calibration;
    no_dvl.dvl.reset();
    ImuBuffer imu(*run.calibration.imu, 0.1);
    AcousticInitializer init(no_dvl, run.dock);
    Fed fed;
    std::string why;
    FeedUpTo(run, fixes, run.frames.back().t_ns, &imu, &init, &fed);
    EXPECT_FALSE(init.Solve(imu, run.frames.back().t_ns, &why).has_value());
    EXPECT_THAT(why, HasSubstr("DVL and acoustic sensor"));
  }
  // Bottom lock lost for 2 s at 8-10 s: the path restarts after it.
  for (DvlMeasurement& d : run.dvl) {
    const double t = static_cast<double>(d.t_ns - run.dvl.front().t_ns) * 1e-9;
    if (t > 8.0 && t < 10.0) d.v_S.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  ImuBuffer imu(*run.calibration.imu, 0.1);
  AcousticInitializer init(run.calibration, run.dock);
  Fed fed;
  std::string why;
  const int64_t t_after = run.dvl.front().t_ns + 11'500'000'000;
  FeedUpTo(run, fixes, t_after, &imu, &init, &fed);
  EXPECT_FALSE(init.Solve(imu, t_after, &why).has_value());
  EXPECT_THAT(why, HasSubstr("fixes on the DVL's path"));
}

TEST(AcousticInitializerTest, RejectsOptionsOutOfRange) {
  const test::SyntheticRun run = MakeFarApproach();
  AcousticInitOptions options;
  options.min_fixes = 2;
  EXPECT_THROW(AcousticInitializer(run.calibration, run.dock, options),
               std::invalid_argument);
  DockModel weightless = run.dock;
  weightless.gravity_D.setZero();
  EXPECT_THROW(AcousticInitializer(run.calibration, weightless), std::invalid_argument);
}

// With an AHRS (2 degrees) the heading is measured: the first fix starts it, within the first
// second, with the heading within 3 of the sensor's sigma, and a position covariance that covers
// an outlier (the fix is unconfirmed); with two fixes required, the second fix starts it.
TEST(AcousticInitializerTest, WithAHeadingSensorOneFixStartsItUnconfirmed) {
  Scenario scenario = test::LongApproachScenario(20.0);
  scenario.dvl_faults.gross_error_probability = 0.0;
  scenario.heading = HeadingCalibration{};
  scenario.heading->sigma_rad = 2.0 * M_PI / 180.0;
  scenario.dock.heading_rad = 1.0;
  const test::SyntheticRun run = test::MakeSyntheticRun(scenario, 3);
  ASSERT_FALSE(run.heading.empty());
  const std::vector<AcousticFix> fixes = test::MakeAcousticFixes(run, 14);
  for (const int min_fixes : {1, 2}) {
    SCOPED_TRACE(min_fixes);
    ImuBuffer imu(*run.calibration.imu, 0.1);
    AcousticInitOptions options;
    options.min_fixes_with_heading = min_fixes;
    AcousticInitializer init(run.calibration, run.dock, options);
    Fed fed;
    size_t next_heading = 0;
    std::string why;
    std::optional<InitialState> state;
    size_t k = 0;
    for (; k < run.frames.size() && !state; ++k) {
      const int64_t t = run.frames[k].t_ns;
      FeedUpTo(run, fixes, t, &imu, &init, &fed);
      while (next_heading < run.heading.size() && run.heading[next_heading].t_ns <= t) {
        init.AddHeading(run.heading[next_heading++]);
      }
      state = init.Solve(imu, t, &why);
    }
    ASSERT_TRUE(state) << "no start: " << why;
    --k;
    EXPECT_TRUE(state->heading_measured);
    EXPECT_EQ(state->fixes_used, min_fixes);
    EXPECT_EQ(state->unconfirmed, min_fixes == 1);
    const int64_t since_start = run.frames[k].t_ns - run.frames.front().t_ns;
    EXPECT_LT(since_start, (min_fixes == 1 ? 1'000'000'000 : 2'000'000'000));
    EXPECT_LE(std::abs(HeadingError(state->T_D_B, run.truth[k].T_D_B)),
              3.0 * state->heading_sigma_rad);
    EXPECT_LT((state->T_D_B.p - run.truth[k].T_D_B.p).head<2>().norm(), 0.5);
    const double sigma_x = std::sqrt(state->pose_covariance(0, 0));
    if (min_fixes == 1) {
      EXPECT_GT(sigma_x, options.unconfirmed_fix_sigma_m);  // covers an outlier
    } else {
      EXPECT_LT(sigma_x, 0.5);
    }
  }
}

}  // namespace
}  // namespace auvdock
