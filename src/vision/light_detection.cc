#include "auvdock/vision/light_detection.h"

#include <algorithm>
#include <cmath>

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

double TypicalPixelSigma(const std::vector<LightDetection>& detections, double floor_sigma_px) {
  std::vector<double> claimed;
  for (const LightDetection& d : detections) {
    const double own = std::sqrt(d.covariance.trace() / 2.0);
    if (std::isfinite(own) && own > 0.0) claimed.push_back(own);
  }
  if (claimed.empty()) return floor_sigma_px;
  std::nth_element(claimed.begin(), claimed.begin() + claimed.size() / 2, claimed.end());
  return std::max(floor_sigma_px, claimed[claimed.size() / 2]);
}

Eigen::Matrix2d PixelCovarianceForPose(const LightDetection& detection, double typical_sigma_px,
                                       double doubt_ratio) {
  const Eigen::Matrix2d own = PixelCovarianceAtLeast(detection, typical_sigma_px);
  if (std::sqrt(own.trace() / 2.0) > doubt_ratio * typical_sigma_px) return own;
  return typical_sigma_px * typical_sigma_px * Eigen::Matrix2d::Identity();
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
