#include "auvdock/vision/identified_light_pose.h"

#include <cmath>
#include <stdexcept>

#include "auvdock/estimator/adaptive_noise_scale.h"
#include "auvdock/vision/pnp_solver.h"

namespace auvdock {

IdentifiedLightPose PoseFromIdentifiedLights(const CameraCalibration& camera,
                                             const DockModel& dock,
                                             const std::vector<LightDetection>& detections,
                                             const std::vector<int>& light_ids,
                                             const Pose3& start,
                                             const IdentifiedLightPoseOptions& options) {
  if (options.min_lights < 4 || !(options.consistency_alpha > 0.0) ||
      !(options.max_start_angle_deg > 0.0)) {
    throw std::invalid_argument("IdentifiedLightPoseOptions out of range");
  }
  IdentifiedLightPose result;
  const double sigma = TypicalPixelSigma(detections, camera.pixel_noise_px);
  result.pixel_sigma_px = sigma;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Matrix2d> covariances;
  for (size_t i = 0; i < detections.size() && i < light_ids.size(); ++i) {
    const DockLight* light = light_ids[i] >= 0 ? dock.FindLight(light_ids[i]) : nullptr;
    if (!light) continue;
    points.push_back(light->p_D);
    pixels.push_back(detections[i].uv);
    covariances.push_back(PixelCovarianceForPose(detections[i], sigma));
  }
  const int n = static_cast<int>(points.size());
  if (n < options.min_lights) {
    result.reason = std::to_string(n) + " identified lights (need " +
                    std::to_string(options.min_lights) + ")";
    return result;
  }
  PnpOptions pnp;
  pnp.pixel_sigma = sigma;
  const PnpResult pose = SolvePnp(points, pixels, camera.intrinsics, pnp, start, covariances);
  if (!pose.ok) {
    result.reason = "pnp: " + pose.reason;
    return result;
  }
  if (pose.dof > 0 && 1.0 - ChiSquareCdf(pose.dof, pose.chi2) < options.consistency_alpha) {
    result.reason = "the " + std::to_string(n) +
                    " identified lights are not consistent with one pose at their pixel noise "
                    "(chi-square " + std::to_string(std::lround(pose.chi2)) + ", " +
                    std::to_string(pose.dof) + " degrees of freedom)";
    return result;
  }
  const double turn_deg = RotationAngleBetween(pose.T_C_D.q, start.q) * 180.0 / M_PI;
  if (turn_deg > options.max_start_angle_deg) {
    result.reason = "the pose of the identified lights is " + std::to_string(std::lround(turn_deg)) +
                    " deg from the walk's";
    return result;
  }
  if (!CameraAboveTheDeck(dock, pose.T_C_D, options.deck)) {
    result.reason = "the camera would be edge-on to the deck or under it";
    return result;
  }
  result.T_C_D = pose.T_C_D;
  result.covariance_local = pose.covariance_local;
  result.rms_px = pose.rms_px;
  result.num_lights = n;
  return result;
}

}  // namespace auvdock
