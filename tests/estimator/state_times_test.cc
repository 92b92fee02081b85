#include "auvdock/estimator/state_times.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

TEST(StateTimesWithoutCameras, OnePerPeriodFromOnePeriodAfterTheFirstSample) {
  const std::vector<int64_t> t = StateTimesWithoutCameras(1'000'000'000, 2'000'000'000, 4.0);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0], 1'250'000'000);
  EXPECT_EQ(t[3], 2'000'000'000);
  // A rate that does not divide a second: no drift over an hour at 3 Hz.
  const std::vector<int64_t> hour = StateTimesWithoutCameras(0, 3'600'000'000'000, 3.0);
  EXPECT_EQ(hour.size(), 10800u);
  EXPECT_EQ(hour.back(), 3'600'000'000'000);
  EXPECT_TRUE(StateTimesWithoutCameras(0, 100, 10.0).empty());
}

TEST(StateTimesWithoutCameras, RejectsABadRate) {
  EXPECT_THROW(StateTimesWithoutCameras(0, 1, 0.0), std::invalid_argument);
  EXPECT_THROW(StateTimesWithoutCameras(0, 1, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
