#include "auvdock/io/imu_time_base.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace auvdock {
namespace {

using ::testing::HasSubstr;

std::vector<ImuSample> Samples(int n, double interval_ns,
                               int64_t t0_ns = 1'700'000'000'000'000'000) {
  std::vector<ImuSample> samples(n);
  for (int k = 0; k < n; ++k) {
    samples[k].t_ns = t0_ns + static_cast<int64_t>(k * interval_ns);
  }
  return samples;
}

ImuCalibration At100Hz() {
  ImuCalibration imu;
  imu.rate_hz = 100.0;
  return imu;
}

TEST(ImuTimeBase, ARateThatAgreesWithTheCalibrationPasses) {
  EXPECT_EQ(ImuTimeBaseProblem(Samples(200, 1e7), At100Hz(), "imu0/data.csv"), "");
  // Jitter and a gap do not move the median.
  std::vector<ImuSample> samples = Samples(200, 1e7);
  for (size_t k = 100; k < samples.size(); ++k) samples[k].t_ns += 3'000'000'000;
  samples[50].t_ns += 4'000'000;
  EXPECT_EQ(ImuTimeBaseProblem(samples, At100Hz(), "imu0/data.csv"), "");
  // Too few samples to tell.
  EXPECT_EQ(ImuTimeBaseProblem(Samples(5, 1e9), At100Hz(), "imu0/data.csv"), "");
}

TEST(ImuTimeBase, TimeStampsInAnotherUnitAreRefusedWithTheirLikelyCause) {
  // 100 Hz stamped in whole seconds: the samples within a second share a stamp, the repeated
  // ones are skipped on reading, and one a second is left.
  const std::string problem =
      ImuTimeBaseProblem(Samples(200, 1e9, 1'700'000'000), At100Hz(), "imu0/data.csv");
  EXPECT_THAT(problem, HasSubstr("imu0/data.csv"));
  EXPECT_THAT(problem, HasSubstr("rate_hz 100"));
  EXPECT_THAT(problem, HasSubstr("whole seconds instead of nanoseconds"));
  EXPECT_THAT(ImuTimeBaseProblem(Samples(200, 1e4), At100Hz(), "f"),
              HasSubstr("microseconds instead of nanoseconds"));
  EXPECT_THAT(ImuTimeBaseProblem(Samples(200, 10.0), At100Hz(), "f"),
              HasSubstr("milliseconds instead of nanoseconds"));
}

TEST(ImuTimeBase, AnImuAtATenthOfItsRateIsRefused) {
  const std::string problem = ImuTimeBaseProblem(Samples(200, 1e8), At100Hz(), "imu0/data.csv");
  EXPECT_THAT(problem, HasSubstr("10 Hz against 100 Hz"));
  EXPECT_THAT(problem, HasSubstr("not this IMU's"));
}

}  // namespace
}  // namespace auvdock
