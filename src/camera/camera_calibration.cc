#include "auvdock/camera/camera_calibration.h"

namespace auvdock {

const char* CameraRoleName(CameraRole role) {
  switch (role) {
    case CameraRole::kStereoLeft:
      return "stereo_left";
    case CameraRole::kStereoRight:
      return "stereo_right";
    case CameraRole::kMono:
      return "mono";
    case CameraRole::kOther:
      break;
  }
  return "other";
}

bool ParseCameraRole(const std::string& text, CameraRole* role) {
  for (CameraRole r : {CameraRole::kStereoLeft, CameraRole::kStereoRight, CameraRole::kMono,
                       CameraRole::kOther}) {
    if (text == CameraRoleName(r)) {
      *role = r;
      return true;
    }
  }
  return false;
}

}  // namespace auvdock
