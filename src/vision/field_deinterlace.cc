#include "auvdock/vision/field_deinterlace.h"

namespace auvdock {

cv::Mat LineDoubleEvenField(const cv::Mat& image) {
  cv::Mat out = image.clone();
  for (int y = 1; y < image.rows; y += 2) {
    if (y + 1 < image.rows) {
      cv::addWeighted(image.row(y - 1), 0.5, image.row(y + 1), 0.5, 0.0, out.row(y));
    } else {
      image.row(y - 1).copyTo(out.row(y));
    }
  }
  return out;
}

}  // namespace auvdock
