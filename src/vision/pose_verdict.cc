#include "auvdock/vision/pose_verdict.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace auvdock {

PoseVerdict::PoseVerdict(const DockModel& dock, const PinholeRadtanCamera& camera,
                         const Pose3& T_C_D, const Eigen::Matrix<double, 6, 6>& covariance_local,
                         double rms_px, int num_lights, const PoseVerdictOptions& options)
    : predicted_(PredictLights(dock, camera, T_C_D, covariance_local, {})),
      rms_px_(rms_px),
      options_(options) {
  if (!(options.gate_sigmas >= 0.0) || !(options.floor_px >= 0.0) ||
      !(options.min_support >= 0.0 && options.min_support <= 1.0)) {
    throw std::invalid_argument("PoseVerdictOptions out of range");
  }
  judges_ = num_lights >= options.min_support * static_cast<double>(predicted_.size());
}

bool PoseVerdict::NearALight(const LightDetection& detection,
                             const std::vector<int>& taken_ids) const {
  const double g = options_.gate_sigmas;
  return std::any_of(predicted_.begin(), predicted_.end(), [&](const PredictedLight& p) {
    if (std::find(taken_ids.begin(), taken_ids.end(), p.light_id) != taken_ids.end()) {
      return false;
    }
    const double sigma = std::sqrt(std::max(0.0, p.covariance.eigenvalues().real().maxCoeff()));
    const double radius = g * sigma + std::max({options_.floor_px, p.radius_px, g * rms_px_});
    return (detection.uv - p.uv).norm() <= radius;
  });
}

std::vector<bool> NoLightOfTheDock(const std::vector<LightDetection>& detections,
                                   const std::vector<int>& ids, const PoseVerdict& verdict) {
  std::vector<bool> none(detections.size(), false);
  if (!verdict.judges()) return none;
  std::vector<int> taken;
  for (int id : ids) {
    if (id >= 0) taken.push_back(id);
  }
  for (size_t i = 0; i < detections.size(); ++i) {
    if (i < ids.size() && ids[i] >= 0) continue;
    none[i] = !verdict.NearALight(detections[i], taken);
  }
  return none;
}

bool ExplainsMostOfItsView(const DockModel& dock, const PinholeRadtanCamera& camera,
                           const Pose3& T_C_D, int identified, double min_support,
                           const RansacMatcherOptions& view) {
  if (!CameraAboveTheDeck(dock, T_C_D, view)) return false;
  const size_t in_view =
      PredictLights(dock, camera, T_C_D, Eigen::Matrix<double, 6, 6>::Zero(), {}).size();
  return identified >= min_support * static_cast<double>(in_view);
}

}  // namespace auvdock
