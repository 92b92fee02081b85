// The pose of a frame whose lights were identified without a pose of its own: by a walk from the
// posed frames beside it (two_way_light_bridge.h), where the frame alone was ambiguous (a ring
// seen in part: two labellings explain its lights equally), or failed.
//
// PnP (SolvePnp) on the identified lights, started at the walk's pose (which also chooses
// between the two minima of a planar layout seen nearly face-on), each light weighed as
// MonoLightPoser weighs it (PixelCovarianceForPose at the frame's typical sigma,
//   sigma = TypicalPixelSigma(detections, camera pixel_noise_px)),
// the covariance widened by the a-posteriori variance factor. Kept when
//   - at least min_lights are identified (4: 3 lights fit any pose exactly, nothing checks them);
//   - the residuals are consistent with those covariances: P(chi-square(2 n - 6) > chi2) >=
//     consistency_alpha (the tracking matcher's test); while they are not, the light without
//     which the others fit best (least chi-square) is left out (a glint the walk took for a
//     light, a centroid pulled by a neighbour's glow), down to min_lights;
//   - the pose is within max_start_angle_deg of the walk's rotation (the walk's labels came from
//     its pose: a PnP minimum far from it is not the pose they describe);
//   - the camera is above the deck (CameraAboveTheDeck, as every pose of MonoLightPoser).
// Otherwise no pose, with the reason.
//
// Units: pixels, metres, degrees; T_C_D maps dock coordinates into the camera frame (OpenCV).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"
#include "auvdock/vision/ransac_matcher.h"

namespace auvdock {

struct IdentifiedLightPoseOptions {
  int min_lights = 4;
  double consistency_alpha = 1e-4;
  double max_start_angle_deg = 10.0;
  RansacMatcherOptions deck;  // CameraAboveTheDeck's limits
};

struct IdentifiedLightPose {
  std::optional<Pose3> T_C_D;
  // Per detection: the light id the pose used, -1 for one left out or never identified.
  std::vector<int> light_ids;
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
  double rms_px = 0.0;
  double pixel_sigma_px = 0.0;
  int num_lights = 0;
  std::string reason;  // why there is no pose (empty with one)
};

// light_ids: per detection, the dock light id or -1; start: the walk's pose of the frame.
IdentifiedLightPose PoseFromIdentifiedLights(const CameraCalibration& camera, const DockModel& dock,
                                             const std::vector<LightDetection>& detections,
                                             const std::vector<int>& light_ids, const Pose3& start,
                                             const IdentifiedLightPoseOptions& options = {});

}  // namespace auvdock
