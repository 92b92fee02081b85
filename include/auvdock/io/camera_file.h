// Loads one camera's calibration from either of the two files users have:
//   - a dataset's calibration.yaml (auvdock format; the camera chosen by name, or the only one)
//   - an OpenCV FileStorage calibration (as written by OpenCV's calibration sample:
//     camera_matrix, distortion_coefficients, image_width, image_height), where no name is
//     needed. Extrinsics are then unknown and T_B_C is the identity.
// A file without distortion coefficients is an error (a silent zero distortion would bias every
// pose). Throws InputError naming the file and key.
#pragma once

#include <string>

#include "auvdock/camera/camera_calibration.h"

namespace auvdock {

CameraCalibration LoadCameraCalibration(const std::string& path, const std::string& camera_name);

}  // namespace auvdock
