#include "auvdock/vision/light_detection.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

TEST(PixelCovarianceAtLeast, NoOwnCovarianceGivesTheFloor) {
  LightDetection d;  // covariance all zero: the detector measured none
  EXPECT_TRUE(PixelCovarianceAtLeast(d, 0.3).isApprox(0.09 * Eigen::Matrix2d::Identity()));
  d.covariance(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(PixelCovarianceAtLeast(d, 0.3).isApprox(0.09 * Eigen::Matrix2d::Identity()));
}

TEST(PixelCovarianceAtLeast, RaisesOnlyTheDirectionsBelowTheFloor) {
  // A centre smeared along the diagonal: 4 px^2 along (1, 1), 0.01 px^2 across it.
  const Eigen::Vector2d along = Eigen::Vector2d(1.0, 1.0).normalized();
  const Eigen::Vector2d across(-along.y(), along.x());
  LightDetection d;
  d.covariance = 4.0 * along * along.transpose() + 0.01 * across * across.transpose();
  const Eigen::Matrix2d raised = PixelCovarianceAtLeast(d, 0.3);
  EXPECT_NEAR(along.dot(raised * along), 4.0, 1e-12);
  EXPECT_NEAR(across.dot(raised * across), 0.09, 1e-12);
  EXPECT_NEAR(along.dot(raised * across), 0.0, 1e-12);
  // Above the floor in every direction: unchanged.
  d.covariance << 1.0, 0.2, 0.2, 0.5;
  EXPECT_TRUE(PixelCovarianceAtLeast(d, 0.3).isApprox(d.covariance, 1e-12));
}

}  // namespace
}  // namespace auvdock
