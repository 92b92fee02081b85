// Calibration of one camera of the rig: intrinsics, extrinsics T_B_C, rate and role.
//
// T_B_C maps camera coordinates (OpenCV: x right, y down, z optical axis) into the body frame B
// (x forward, y right, z down, origin at the IMU). Seed 004's rig: a forward-down stereo pair
// (roles stereo_left / stereo_right) and a down-looking mono camera (role mono).
#pragma once

#include <string>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/pose3.h"

namespace auvdock {

enum class CameraRole { kStereoLeft, kStereoRight, kMono, kOther };

const char* CameraRoleName(CameraRole role);
// Parses "stereo_left", "stereo_right", "mono", "other"; returns false on anything else.
bool ParseCameraRole(const std::string& text, CameraRole* role);

struct CameraCalibration {
  std::string name;  // also the dataset folder name, e.g. "cam0"
  CameraRole role = CameraRole::kOther;
  PinholeRadtanCamera intrinsics;
  Pose3 T_B_C;
  double rate_hz = 10.0;
  double pixel_noise_px = 0.3;  // 1-sigma centroid noise assumed for a detected light
};

}  // namespace auvdock
