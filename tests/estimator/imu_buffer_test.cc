#include "auvdock/estimator/imu_buffer.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

ImuBuffer FilledBuffer(double noise_scale) {
  ImuBuffer buffer(ImuCalibration(), 0.1, noise_scale);
  for (int k = 0; k <= 200; ++k) {
    ImuSample s;
    s.t_ns = k * 5000000LL;
    s.gyro = Eigen::Vector3d(0.01, -0.02, 0.03);
    s.accel = Eigen::Vector3d(0.1, 0.0, -9.81);
    EXPECT_EQ(buffer.Add(s), "");
  }
  return buffer;
}

// The noise scale multiplies the sigmas, so the preintegrated covariance grows by its square;
// the deltas themselves do not change.
TEST(ImuBufferTest, TheNoiseScaleScalesThePreintegratedCovarianceByItsSquare) {
  const ImuBuffer plain = FilledBuffer(1.0);
  const ImuBuffer inflated = FilledBuffer(3.0);
  const auto a = plain.Preintegrate(0, 1000000000LL, ImuBias());
  const auto b = inflated.Preintegrate(0, 1000000000LL, ImuBias());
  ASSERT_TRUE(a && b);
  EXPECT_LT((b->covariance() - 9.0 * a->covariance()).norm(), 1e-9 * b->covariance().norm());
  EXPECT_LT((b->delta_p() - a->delta_p()).norm(), 1e-15);
}

TEST(ImuBufferTest, GyroAtHoldsTheLastSampleAndSaysNothingInAGap) {
  const ImuBuffer buffer = FilledBuffer(1.0);
  ASSERT_TRUE(buffer.GyroAt(7000000LL));
  EXPECT_DOUBLE_EQ(buffer.GyroAt(7000000LL)->z(), 0.03);
  EXPECT_FALSE(buffer.GyroAt(-1));            // before the first sample
  EXPECT_FALSE(buffer.GyroAt(2000000000LL));  // 1 s after the last: beyond max_gap_s
}

TEST(ImuBufferTest, RejectsANonPositiveNoiseScale) {
  EXPECT_THROW(ImuBuffer(ImuCalibration(), 0.1, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
