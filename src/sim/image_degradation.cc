#include "auvdock/sim/image_degradation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/sim/random_stream.h"

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The image sampled at (u + shift.x, v + shift.y): bilinear, the border replicated.
cv::Mat Shifted(const cv::Mat& image, const Eigen::Vector2d& shift) {
  const cv::Matx23d translation(1.0, 0.0, -shift.x(), 0.0, 1.0, -shift.y());
  cv::Mat out;
  cv::warpAffine(image, out, translation, image.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

}  // namespace

FrameDegradation DrawFrameDegradation(const RenderLook& look, std::mt19937_64& rng) {
  FrameDegradation frame;
  if (look.max_motion_blur_px > 0.0) {
    frame.motion_blur_px = look.max_motion_blur_px * Uniform01(rng);
    frame.motion_blur_angle_rad = kPi * Uniform01(rng);
  }
  if (look.interlaced) {
    frame.field_offset_px = look.field_offset_sigma_px *
                            Eigen::Vector2d(StandardNormal(rng), StandardNormal(rng));
  }
  if (look.jpeg_quality_max > 0) {
    const int span = look.jpeg_quality_max - look.jpeg_quality_min + 1;
    frame.jpeg_quality =
        look.jpeg_quality_min + std::min(span - 1, static_cast<int>(Uniform01(rng) * span));
  }
  return frame;
}

cv::Mat MotionBlurKernel(double length_px, double angle_rad) {
  const int half = static_cast<int>(std::ceil(0.5 * length_px + 1.0));
  cv::Mat kernel = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
  // Samples spread evenly along the segment, each splatted bilinearly: symmetric about the centre.
  const int samples = std::max(2, static_cast<int>(std::ceil(8.0 * length_px)));
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  for (int i = 0; i < samples; ++i) {
    const double t = length_px * ((i + 0.5) / samples - 0.5);
    const double x = half + t * c, y = half + t * s;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double ax = x - x0, ay = y - y0;
    kernel.at<float>(y0, x0) += static_cast<float>((1 - ax) * (1 - ay));
    kernel.at<float>(y0, x0 + 1) += static_cast<float>(ax * (1 - ay));
    kernel.at<float>(y0 + 1, x0) += static_cast<float>((1 - ax) * ay);
    kernel.at<float>(y0 + 1, x0 + 1) += static_cast<float>(ax * ay);
  }
  kernel /= cv::sum(kernel)[0];
  return kernel;
}

void ApplyOpticsAndFields(const RenderLook& look, const FrameDegradation& frame, cv::Mat* image) {
  if (image->type() != CV_32FC3) throw std::invalid_argument("ApplyOpticsAndFields: CV_32FC3");
  if (look.defocus_sigma_px > 0.05) {
    cv::GaussianBlur(*image, *image, cv::Size(0, 0), look.defocus_sigma_px, look.defocus_sigma_px,
                     cv::BORDER_REPLICATE);
  }
  if (frame.motion_blur_px > 0.25) {
    cv::filter2D(*image, *image, -1, MotionBlurKernel(frame.motion_blur_px,
                                                      frame.motion_blur_angle_rad),
                 cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  }
  if (look.interlaced && frame.field_offset_px.squaredNorm() > 0.0) {
    const cv::Mat first = Shifted(*image, 0.5 * frame.field_offset_px);
    const cv::Mat second = Shifted(*image, -0.5 * frame.field_offset_px);
    for (int v = 0; v < image->rows; ++v) {
      (v % 2 == 0 ? first : second).row(v).copyTo(image->row(v));
    }
  }
}

void ApplyColourCast(const RenderLook& look, cv::Mat* image) {
  if (look.colour_cast_bgr.isApprox(Eigen::Vector3d::Ones())) return;
  cv::multiply(*image, cv::Scalar(look.colour_cast_bgr[0], look.colour_cast_bgr[1],
                                  look.colour_cast_bgr[2]),
               *image);
}

cv::Mat ApplyJpeg(const FrameDegradation& frame, const cv::Mat& image) {
  if (frame.jpeg_quality <= 0) return image;
  std::vector<uchar> bytes;
  cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, frame.jpeg_quality});
  return cv::imdecode(bytes, cv::IMREAD_COLOR);
}

}  // namespace auvdock
