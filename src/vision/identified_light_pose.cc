#include "auvdock/vision/identified_light_pose.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "auvdock/estimator/adaptive_noise_scale.h"
#include "auvdock/vision/pnp_solver.h"

namespace auvdock {

IdentifiedLightPose PoseFromIdentifiedLights(const CameraCalibration& camera, const DockModel& dock,
                                             const std::vector<LightDetection>& detections,
                                             const std::vector<int>& light_ids, const Pose3& start,
                                             const IdentifiedLightPoseOptions& options) {
  if (options.min_lights < 4 || !(options.consistency_alpha > 0.0) ||
      !(options.max_start_angle_deg > 0.0)) {
    throw std::invalid_argument("IdentifiedLightPoseOptions out of range");
  }
  IdentifiedLightPose result;
  const double sigma = TypicalPixelSigma(detections, camera.pixel_noise_px);
  result.pixel_sigma_px = sigma;
  std::vector<int> used(detections.size(), -1);  // the light of each detection in the pose
  for (size_t i = 0; i < detections.size() && i < light_ids.size(); ++i) {
    if (light_ids[i] >= 0 && dock.FindLight(light_ids[i])) used[i] = light_ids[i];
  }
  PnpOptions pnp;
  pnp.pixel_sigma = sigma;
  // The pose of the detections that lights gives a light id.
  auto solve = [&](const std::vector<int>& lights) {
    std::vector<Eigen::Vector3d> points;
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Matrix2d> covariances;
    for (size_t i = 0; i < lights.size(); ++i) {
      if (lights[i] < 0) continue;
      points.push_back(dock.FindLight(lights[i])->p_D);
      pixels.push_back(detections[i].uv);
      covariances.push_back(PixelCovarianceForPose(detections[i], sigma));
    }
    return SolvePnp(points, pixels, camera.intrinsics, pnp, start, covariances);
  };
  auto consistent = [&](const PnpResult& pose) {
    return pose.ok &&
           (pose.dof == 0 || 1.0 - ChiSquareCdf(pose.dof, pose.chi2) >= options.consistency_alpha);
  };
  auto count = [](const std::vector<int>& lights) {
    return static_cast<int>(
        std::count_if(lights.begin(), lights.end(), [](int id) { return id >= 0; }));
  };
  if (count(used) < options.min_lights) {
    result.reason = std::to_string(count(used)) + " identified lights (need " +
                    std::to_string(options.min_lights) + ")";
    return result;
  }
  PnpResult pose = solve(used);
  // While the lights do not fit one pose, leave out the one without which the rest fit best.
  while (pose.ok && !consistent(pose) && count(used) > options.min_lights) {
    std::optional<std::pair<PnpResult, size_t>> best;
    for (size_t i = 0; i < used.size(); ++i) {
      if (used[i] < 0) continue;
      std::vector<int> fewer = used;
      fewer[i] = -1;
      PnpResult candidate = solve(fewer);
      if (candidate.ok && (!best || candidate.chi2 < best->first.chi2)) {
        best.emplace(std::move(candidate), i);
      }
    }
    if (!best) break;
    used[best->second] = -1;
    pose = std::move(best->first);
  }
  if (!pose.ok) {
    result.reason = "pnp: " + pose.reason;
    return result;
  }
  if (!consistent(pose)) {
    result.reason = "the " + std::to_string(count(used)) +
                    " identified lights are not consistent with one pose at their pixel noise "
                    "(chi-square " +
                    std::to_string(std::lround(pose.chi2)) + ", " + std::to_string(pose.dof) +
                    " degrees of freedom)";
    return result;
  }
  result.num_lights = count(used);
  const double turn_deg = RotationAngleBetween(pose.T_C_D.q, start.q) * 180.0 / M_PI;
  if (turn_deg > options.max_start_angle_deg) {
    result.reason = "the pose of the identified lights is " +
                    std::to_string(std::lround(turn_deg)) + " deg from the walk's";
    return result;
  }
  if (!CameraAboveTheDeck(dock, pose.T_C_D, options.deck)) {
    result.reason = "the camera would be edge-on to the deck or under it";
    return result;
  }
  result.T_C_D = pose.T_C_D;
  result.light_ids = used;
  result.covariance_local = pose.covariance_local;
  result.rms_px = pose.rms_px;
  return result;
}

}  // namespace auvdock
