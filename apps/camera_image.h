// One camera image of a dataset, decoded for the front-end: BGR, 8 bits, the calibrated size.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock::cli {

// The image of `frame`; an empty one and `problem` set ("missing ...", "cannot decode", "is
// WxH, calibration says W'xH'") when it cannot be used.
cv::Mat ReadCameraImage(const CameraFrame& frame, const CameraCalibration& camera,
                        std::string* problem);

}  // namespace auvdock::cli
