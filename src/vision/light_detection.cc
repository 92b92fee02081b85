#include "auvdock/vision/light_detection.h"

#include <algorithm>

#include <Eigen/Eigenvalues>

namespace auvdock {

Eigen::Matrix2d PixelCovarianceAtLeast(const LightDetection& detection, double floor_sigma_px) {
  const double floor = floor_sigma_px * floor_sigma_px;
  const Eigen::Matrix2d& own = detection.covariance;
  if (!own.allFinite() || !(own.trace() > 0.0)) return floor * Eigen::Matrix2d::Identity();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(0.5 * (own + own.transpose()));
  const Eigen::Vector2d raised = eigen.eigenvalues().cwiseMax(floor);
  return eigen.eigenvectors() * raised.asDiagonal() * eigen.eigenvectors().transpose();
}

const char* MatchStatusName(MatchStatus status) {
  switch (status) {
    case MatchStatus::kOk:
      return "ok";
    case MatchStatus::kAmbiguous:
      return "ambiguous";
    case MatchStatus::kFailed:
      break;
  }
  return "failed";
}

}  // namespace auvdock
