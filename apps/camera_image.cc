#include "apps/camera_image.h"

#include <filesystem>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

namespace auvdock::cli {

cv::Mat ReadCameraImage(const CameraFrame& frame, const CameraCalibration& camera,
                        std::string* problem) {
  problem->clear();
  std::error_code error;
  if (!std::filesystem::is_regular_file(frame.path, error)) {
    *problem = "missing (listed in the camera's data.csv, not in its data/ folder)";
    return cv::Mat();
  }
  cv::Mat image = cv::imread(frame.path, cv::IMREAD_COLOR);
  if (image.empty()) {
    *problem = "cannot decode";
  } else if (image.cols != camera.intrinsics.width() || image.rows != camera.intrinsics.height()) {
    *problem = "is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
               ", calibration says " + std::to_string(camera.intrinsics.width()) + "x" +
               std::to_string(camera.intrinsics.height());
  }
  return problem->empty() ? image : cv::Mat();
}

}  // namespace auvdock::cli
