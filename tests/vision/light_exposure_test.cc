// The detector across exposures, on scenes drawn here (tests/testing/led_image.h): an image that
// clips below 255 (a gain applied past the clip, limited-range video) and an overexposed one whose
// LEDs clip together with the bright structure they touch. And the core's separation from that
// structure (light_core_centroid.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/vision/blob_light_detector.h"
#include "auvdock/vision/light_core_centroid.h"
#include "tests/testing/led_image.h"

namespace auvdock {
namespace {

using test::AddLed;
using test::Led;

// Six LEDs (clipped cores of 6 px radius in a tight glow) on a dark blue-green background round a
// white funnel that clips, through a camera that
// clips at 255, then scaled by `gain_after_clip` (so the image clips at 255 gain_after_clip) and
// JPEG-compressed.
struct Scene {
  cv::Mat bgr;
  std::vector<Led> leds;
};

Scene DrawScene(double gain_after_clip) {
  cv::Mat image(480, 640, CV_32FC3, cv::Scalar(70, 80, 40));
  cv::ellipse(image, cv::Point(320, 240), cv::Size(80, 70), 0, 0, 360, cv::Scalar(300, 300, 300),
              cv::FILLED);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  Scene scene;
  for (int k = 0; k < 6; ++k) {
    const double a = 2.0 * 3.14159265358979 * (k + 0.3) / 6.0;
    scene.leds.push_back(
        {Eigen::Vector2d(320.4 + 150.0 * std::cos(a), 240.7 + 130.0 * std::sin(a)), 6.0, 4.5});
    AddLed(scene.leds.back(), &image);
  }
  cv::Mat noise(image.size(), CV_32FC3);
  cv::RNG(3).fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
  image += noise;
  cv::min(image, 255.0, image);
  image *= gain_after_clip;
  image.convertTo(scene.bgr, CV_8UC3);
  std::vector<uchar> buffer;
  cv::imencode(".jpg", scene.bgr, buffer, {cv::IMWRITE_JPEG_QUALITY, 90});
  scene.bgr = cv::imdecode(buffer, cv::IMREAD_COLOR);
  return scene;
}

int LedsFound(const Scene& scene, const std::vector<LightDetection>& found) {
  int n = 0;
  for (const Led& led : scene.leds) {
    n += std::any_of(found.begin(), found.end(),
                     [&](const LightDetection& d) { return (d.uv - led.uv).norm() < 1.0; });
  }
  return n;
}

// Dimmed past the clip, the LEDs' plateaus sit at 153, not 255: they are saturated lights there,
// not flat-topped lit surfaces (without the image's own clip level, every LED is rejected as
// "flat top"), and their contrast is 0.6 of what the response threshold assumes for a full-range
// image.
TEST(LightExposure, LightsOfAnImageThatClipsBelow255AreFound) {
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlue;
  options.checks.min_halo_excess = 15.0;  // a threshold learned from such footage
  const BlobLightDetector detector(options);
  for (const double gain : {1.0, 0.6}) {
    const Scene scene = DrawScene(gain);
    const auto found = detector.Detect(scene.bgr);
    EXPECT_EQ(LedsFound(scene, found), 6) << "gain " << gain;
    EXPECT_EQ(found.size(), 6u) << "gain " << gain;
  }
}

// A saturated disc (a LED's clipped core) touching a saturated rim 4 px wide: at every level the
// flood fill runs along the rim out of the window. The opening cuts the rim off; the centre is
// the disc's to a fraction of a pixel, and the covariance carries the junction's pull.
TEST(LightCore, AClippedLightIsCutFromTheClippedRimItTouches) {
  cv::Mat luma(160, 160, CV_32F, cv::Scalar(60));
  const Eigen::Vector2d centre(80.3, 90.6);
  const double radius = 9.0;
  cv::rectangle(luma, cv::Rect(0, 79, 160, 4), cv::Scalar(255), cv::FILLED);  // the rim
  for (int y = 0; y < luma.rows; ++y) {
    for (int x = 0; x < luma.cols; ++x) {
      const double d = std::hypot(x - centre.x(), y - centre.y());
      if (d <= radius) luma.at<float>(y, x) = 255.0f;
    }
  }
  const double sigma = radius / std::sqrt(2.0);
  LightCoreOptions options;
  const auto core = MeasureLightCore(luma, 80, 90, sigma, 1.0, options);
  ASSERT_TRUE(core.has_value());
  EXPECT_TRUE(core->separated);
  EXPECT_FALSE(core->touches_window);
  EXPECT_LT((core->uv - centre).norm(), 1.0);
  const double pull = options.separated_bias_fraction * core->separation_px;
  EXPECT_GE(core->covariance(1, 1), pull * pull);

  options.neck_cut_sigmas = 0.0;  // without the cut, the rim makes it one extended structure
  const auto joined = MeasureLightCore(luma, 80, 90, sigma, 1.0, options);
  ASSERT_TRUE(joined.has_value());
  EXPECT_TRUE(joined->touches_window);
  EXPECT_FALSE(joined->separated);
}

// A clipped surface wider than the opening (a funnel's interior) stays extended where it is
// touched: the opening does not carve a light out of it.
TEST(LightCore, AWideClippedSurfaceIsNotCutIntoALight) {
  cv::Mat luma(160, 160, CV_32F, cv::Scalar(60));
  cv::rectangle(luma, cv::Rect(70, 0, 90, 160), cv::Scalar(255), cv::FILLED);
  const auto core = MeasureLightCore(luma, 72, 80, 6.0, 1.0, LightCoreOptions{});
  ASSERT_TRUE(core.has_value());
  EXPECT_TRUE(core->touches_window);
  EXPECT_FALSE(core->separated);
}

}  // namespace
}  // namespace auvdock
