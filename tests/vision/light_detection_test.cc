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

TEST(TypicalPixelSigma, TheMedianClaimNeverBelowTheFloor) {
  std::vector<LightDetection> detections(5);
  const double sigmas[] = {0.2, 0.5, 0.6, 4.0, 0.0};  // the last claims nothing
  for (int i = 0; i < 5; ++i) detections[i].covariance = sigmas[i] * sigmas[i] * Eigen::Matrix2d::Identity();
  EXPECT_NEAR(TypicalPixelSigma(detections, 0.3), 0.6, 1e-12);  // median of 0.2, 0.5, 0.6, 4
  EXPECT_NEAR(TypicalPixelSigma(detections, 0.8), 0.8, 1e-12);
  EXPECT_NEAR(TypicalPixelSigma({}, 0.3), 0.3, 1e-12);
}

TEST(PixelCovarianceForPose, AlikeUnlessTheClaimIsFarAboveTheTypical) {
  LightDetection d;
  d.covariance = Eigen::Vector2d(0.9, 0.1).asDiagonal();  // sqrt(trace / 2) = 0.71 px
  // Within twice the typical 0.5 px: weighed like every other light.
  EXPECT_TRUE(PixelCovarianceForPose(d, 0.5).isApprox(0.25 * Eigen::Matrix2d::Identity()));
  // A light cut by the border, 3 px along u: its own covariance, raised to the typical.
  d.covariance = Eigen::Vector2d(9.0, 0.04).asDiagonal();
  const Eigen::Matrix2d doubted = PixelCovarianceForPose(d, 0.5);
  EXPECT_NEAR(doubted(0, 0), 9.0, 1e-12);
  EXPECT_NEAR(doubted(1, 1), 0.25, 1e-12);
  // No claim at all: the typical.
  EXPECT_TRUE(PixelCovarianceForPose(LightDetection{}, 0.3).isApprox(0.09 * Eigen::Matrix2d::Identity()));
}

}  // namespace
}  // namespace auvdock
