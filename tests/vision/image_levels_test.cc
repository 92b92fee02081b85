// The image statistics the detector calibrates itself by: pixel noise, and the level at which an
// image clips (a full-range camera, limited-range video, a gain past the clip), on images drawn
// here.
#include "auvdock/vision/image_levels.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

// A textured grey background with a few bright Gaussian lights and a smooth lit patch; its
// brightest pixel is about 210 (nothing clips).
cv::Mat UnclippedScene() {
  cv::Mat image(240, 320, CV_32F);
  cv::Mat texture(30, 40, CV_32F);
  cv::theRNG().state = 7;
  cv::randn(texture, 0.0, 10.0);
  cv::resize(texture, texture, image.size(), 0, 0, cv::INTER_CUBIC);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      double v = 60.0 + texture.at<float>(y, x);
      v += 90.0 *
           std::exp(-((x - 250.0) * (x - 250.0) + (y - 60.0) * (y - 60.0)) / (2 * 30.0 * 30.0));
      for (const cv::Point2d c :
           {cv::Point2d(60, 50), cv::Point2d(150, 180), cv::Point2d(280, 200)}) {
        v += 150.0 * std::exp(-((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y)) / (2 * 4.0 * 4.0));
      }
      image.at<float>(y, x) = static_cast<float>(v);
    }
  }
  return image;
}

// The scene through a camera of the given gain that clips at `clip` (8 bits), optionally JPEG.
cv::Mat Exposed(const cv::Mat& scene, double gain, double clip, int jpeg_quality = 0) {
  cv::Mat out = scene * gain;
  cv::min(out, clip, out);
  cv::Mat bytes;
  out.convertTo(bytes, CV_8U);
  if (jpeg_quality > 0) {
    std::vector<uchar> buffer;
    cv::imencode(".jpg", bytes, buffer, {cv::IMWRITE_JPEG_QUALITY, jpeg_quality});
    bytes = cv::imdecode(buffer, cv::IMREAD_GRAYSCALE);
  }
  bytes.convertTo(out, CV_32F);
  return out;
}

TEST(EstimatePixelNoise, IsTheSigmaOfWhiteNoiseOnASmoothImage) {
  for (const double sigma : {1.0, 3.0, 8.0}) {
    cv::Mat image(240, 320, CV_32F);
    cv::randn(image, 100.0, sigma);
    EXPECT_NEAR(EstimatePixelNoise(image), sigma, 0.1 * sigma);
  }
}

TEST(EstimateClipLevel, NoneWhereNothingClips) {
  EXPECT_FALSE(EstimateClipLevel(UnclippedScene()).has_value());
  EXPECT_FALSE(EstimateClipLevel(Exposed(UnclippedScene(), 1.0, 255.0, 85)).has_value());
  // A uniform lit disc (a pile-up at its level) with a light brighter than it: no clip.
  cv::Mat surface(200, 300, CV_32F, cv::Scalar(40));
  cv::circle(surface, cv::Point(200, 100), 14, cv::Scalar(123), cv::FILLED);
  for (int y = 0; y < surface.rows; ++y) {
    for (int x = 0; x < surface.cols; ++x) {
      const double d2 = (x - 70.0) * (x - 70.0) + (y - 100.0) * (y - 100.0);
      surface.at<float>(y, x) += static_cast<float>(150.0 * std::exp(-d2 / (2.0 * 3.5 * 3.5)));
    }
  }
  EXPECT_FALSE(EstimateClipLevel(surface).has_value());
  // A dim, flat image: its top is no pile-up.
  EXPECT_FALSE(EstimateClipLevel(Exposed(UnclippedScene(), 0.5, 255.0)).has_value());
}

TEST(EstimateClipLevel, FindsTheLevelWhereAnOverexposedImageClips) {
  for (const double clip : {255.0, 235.0, 150.0}) {
    const auto level = EstimateClipLevel(Exposed(UnclippedScene(), 2.0, clip));
    ASSERT_TRUE(level.has_value()) << clip;
    EXPECT_NEAR(*level, clip, 1.0);
    // JPEG's ringing spreads the plateau's edge over a few levels, above it too.
    const auto compressed = EstimateClipLevel(Exposed(UnclippedScene(), 2.0, clip, 85));
    ASSERT_TRUE(compressed.has_value()) << clip;
    EXPECT_NEAR(*compressed, clip, 2.0);
  }
}

// A flat cyan structure (as renderers draw lit surfaces) is the brightest thing in a dim image:
// its pixels pile up at one luma level with nothing above, like a clip; but a clip is white, it
// flattens every channel. The same structure white at that level is a clip.
TEST(EstimateClipLevel, AFlatColouredSurfaceIsNoClip) {
  for (const bool white : {false, true}) {
    cv::Mat bgr(240, 320, CV_8UC3, cv::Scalar(70, 80, 30));
    const cv::Scalar colour = white ? cv::Scalar(163, 163, 163) : cv::Scalar(200, 190, 60);
    cv::ellipse(bgr, cv::Point(100, 120), cv::Size(40, 30), 0, 0, 360, colour, cv::FILLED);
    cv::Mat luma;
    cv::cvtColor(bgr, luma, cv::COLOR_BGR2GRAY);
    luma.convertTo(luma, CV_32F);
    const auto level = EstimateClipLevel(luma, bgr);
    EXPECT_EQ(level.has_value(), white);
    if (white && level) {
      EXPECT_NEAR(*level, 163.0, 1.0);
    }
    EXPECT_TRUE(EstimateClipLevel(luma).has_value()) << "without colour, a pile-up is a clip";
  }
}

}  // namespace
}  // namespace auvdock
