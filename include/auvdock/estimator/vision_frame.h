// What the estimator takes from the vision front-end for one camera frame: identified lights,
// already associated with the dock model.
//
//   mono:   lights identified in the mono camera's raw (distorted) image, pixels;
//   stereo: lights identified in both stereo images and triangulated, p_S in S = the
//           stereo-left camera frame (OpenCV axes), with the 3 x 3 covariance from the pair's
//           pixel sigma (sigma_px: the larger of the camera's pixel noise and the two
//           detections' own centroid sigmas; 0 where unknown: the camera's pixel noise).
// T_D_B_initial is a per-frame pose (the paper's baseline) used only to initialise or re-seed
// the estimator; it never enters the cost.
//
// Time: the frame's state is at t_ns, the time of its earliest image. Cameras that are not
// synchronised with each other take their images at their own times: the mono image at
// t_ns + mono_dt_ns, the stereo pair (synchronised with itself) at t_ns + stereo_dt_ns, each
// >= 0; the estimator moves those observations to the state's time with the IMU
// (factors/time_shifted_factor.h). Both are 0 for a synchronised rig.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct MonoLightObservation {
  int light_id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // raw image, pixels
  double sigma_px = 0.5;                         // 1-sigma per pixel coordinate
};

struct StereoLightObservation {
  int light_id = -1;
  Eigen::Vector3d p_S = Eigen::Vector3d::Zero();         // m
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of p_S, m^2, at sigma_px
  double sigma_px = 0.0;  // 1-sigma per pixel coordinate of both images; 0: the camera's
};

struct VisionFrame {
  int64_t t_ns = 0;
  std::vector<MonoLightObservation> mono;
  std::vector<StereoLightObservation> stereo;
  std::optional<Pose3> T_D_B_initial;
  int64_t mono_dt_ns = 0;    // mono image time - t_ns
  int64_t stereo_dt_ns = 0;  // stereo pair time - t_ns
  // The identification chose among a symmetric dock's rival poses by nothing (no prediction,
  // gravity, fix or approach side): the lights fix the pose only up to the dock's symmetry.
  bool symmetry_unresolved = false;

  bool empty() const { return mono.empty() && stereo.empty(); }
  // The time of the frame's latest image: it is complete (and may be used) from then on.
  int64_t last_t_ns() const {
    return t_ns + (mono_dt_ns > stereo_dt_ns ? mono_dt_ns : stereo_dt_ns);
  }
};

}  // namespace auvdock
