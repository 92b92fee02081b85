#include "auvdock/vision/dark_channel_dehazer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

cv::Mat Erode(const cv::Mat& src, int window, int border) {
  cv::Mat dst;
  cv::erode(src, dst, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(window, window)),
            cv::Point(-1, -1), 1, border);
  return dst;
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  cv::Mat diff;
  cv::compare(a, b, diff, cv::CMP_NE);
  return cv::countNonZero(diff.reshape(1)) == 0;
}

TEST(MinFilterTest, EqualsErodeWithRectangularKernel) {
  cv::RNG rng(12345);
  const std::vector<cv::Size> sizes = {{53, 37}, {64, 64}, {200, 5}, {3, 101}, {1, 1}, {17, 1}};
  const std::vector<int> windows = {1, 2, 3, 4, 5, 8, 15, 31, 102};
  for (const cv::Size& size : sizes) {
    cv::Mat u8(size, CV_8U);
    rng.fill(u8, cv::RNG::UNIFORM, 0, 256);
    cv::Mat f32(size, CV_32F);
    rng.fill(f32, cv::RNG::NORMAL, 0.0, 100.0);
    for (int window : windows) {
      for (const cv::Mat& src : {u8, f32}) {
        const cv::Mat ours = MinFilter(src, window);
        // erode's default border (constant +max) and a replicated border give the same minimum;
        // both are checked.
        EXPECT_TRUE(Identical(ours, Erode(src, window, cv::BORDER_CONSTANT)))
            << "size " << size << " window " << window << " type " << src.type();
        EXPECT_TRUE(Identical(ours, Erode(src, window, cv::BORDER_REPLICATE)))
            << "size " << size << " window " << window << " type " << src.type();
      }
    }
  }
}

TEST(MinFilterTest, AcceptsNonContinuousRoi) {
  cv::RNG rng(7);
  cv::Mat big(80, 90, CV_8U);
  rng.fill(big, cv::RNG::UNIFORM, 0, 256);
  const cv::Mat roi = big(cv::Rect(5, 7, 41, 33));
  // MinFilter ignores the parent image around a view; cv::erode would read it, so the reference
  // is computed on a copy.
  EXPECT_TRUE(Identical(MinFilter(roi, 9), Erode(roi.clone(), 9, cv::BORDER_REPLICATE)));
}

TEST(MinFilterTest, RejectsBadInput) {
  EXPECT_THROW(MinFilter(cv::Mat(), 3), std::invalid_argument);
  EXPECT_THROW(MinFilter(cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(1)), 3), std::invalid_argument);
  EXPECT_THROW(MinFilter(cv::Mat(4, 4, CV_16U, cv::Scalar::all(1)), 3), std::invalid_argument);
  EXPECT_THROW(MinFilter(cv::Mat(4, 4, CV_8U, cv::Scalar::all(1)), 0), std::invalid_argument);
}

// A hazy scene I = J t + A (1 - t) with known constant t on coloured patches (every patch has one
// zero channel, so the dark channel of J is 0) below a band of open water (t = 0, I = A) from
// which the atmospheric light is read.
struct HazyScene {
  cv::Mat clear;  // J, CV_8UC3
  cv::Mat hazy;   // I, CV_8UC3
  cv::Mat patch_mask;  // CV_8U, 255 on the patches
};

constexpr int kWaterRows = 40;

HazyScene MakeHazyScene(double t, const cv::Vec3d& a) {
  const int rows = 160;
  const int cols = 200;
  const cv::Vec3b colours[] = {{0, 200, 90},  {160, 0, 220}, {60, 130, 0},  {0, 40, 250},
                               {230, 90, 0},  {120, 0, 30},  {0, 255, 255}, {200, 200, 0}};
  HazyScene scene;
  scene.clear = cv::Mat(rows, cols, CV_8UC3);
  scene.hazy = cv::Mat(rows, cols, CV_8UC3);
  scene.patch_mask = cv::Mat::zeros(rows, cols, CV_8U);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      cv::Vec3b& j = scene.clear.at<cv::Vec3b>(y, x);
      cv::Vec3b& i = scene.hazy.at<cv::Vec3b>(y, x);
      if (y < kWaterRows) {  // open water: J is irrelevant, t = 0
        j = cv::Vec3b(static_cast<uint8_t>(a[0]), static_cast<uint8_t>(a[1]),
                      static_cast<uint8_t>(a[2]));
        i = j;
        continue;
      }
      j = colours[((y - kWaterRows) / 30 * 7 + x / 25) % 8];
      for (int c = 0; c < 3; ++c) i[c] = cv::saturate_cast<uint8_t>(j[c] * t + a[c] * (1.0 - t));
      scene.patch_mask.at<uint8_t>(y, x) = 255;
    }
  }
  return scene;
}

double MaxAbsDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  std::vector<cv::Mat> channels;
  cv::split(diff, channels);
  double max_value = 0.0;
  for (const cv::Mat& channel : channels) {
    double channel_max = 0.0;
    cv::minMaxLoc(channel, nullptr, &channel_max, nullptr, nullptr, mask);
    max_value = std::max(max_value, channel_max);
  }
  return max_value;
}

TEST(DarkChannelDehazerTest, RecoversKnownHazeWithFullOmega) {
  const cv::Vec3d a(150.0, 200.0, 110.0);
  const double t = 0.5;
  const HazyScene scene = MakeHazyScene(t, a);

  DehazeOptions options;
  options.omega = 1.0;
  options.t_min = 0.05;
  const DarkChannelDehazer dehazer(options);
  const DarkChannelDehazer::Result result = dehazer.Dehaze(scene.hazy);

  for (int c = 0; c < 3; ++c) EXPECT_NEAR(result.atmospheric_light[c], a[c], 2.0) << c;
  ASSERT_EQ(result.image.type(), CV_8UC3);
  ASSERT_EQ(result.dark_channel.type(), CV_8U);
  ASSERT_EQ(result.transmission.type(), CV_32F);

  // The prior holds on every patch pixel, so t is recovered wherever the window touches a patch.
  double t_lo = 0.0, t_hi = 0.0;
  cv::minMaxLoc(result.transmission, &t_lo, &t_hi, nullptr, nullptr, scene.patch_mask);
  EXPECT_NEAR(t_lo, t, 0.01);
  EXPECT_NEAR(t_hi, t, 0.01);
  // 8-bit rounding of I (half a level) is amplified by 1 / t.
  EXPECT_LE(MaxAbsDifference(result.image, scene.clear, scene.patch_mask), 2.0);
  // Open water is the veiling light itself and stays so.
  EXPECT_LE(MaxAbsDifference(result.image, scene.hazy, 255 - scene.patch_mask), 1.0);
}

TEST(DarkChannelDehazerTest, GuidedRefinementKeepsTransmissionInRange) {
  const HazyScene scene = MakeHazyScene(0.4, cv::Vec3d(140.0, 190.0, 120.0));
  DehazeOptions options;
  options.omega = 1.0;
  options.t_min = 0.05;
  options.refine_with_guided_filter = true;
  options.guided_radius = 8;
  const DarkChannelDehazer::Result result = DarkChannelDehazer(options).Dehaze(scene.hazy);
  double t_lo = 0.0, t_hi = 0.0;
  cv::minMaxLoc(result.transmission, &t_lo, &t_hi);
  EXPECT_GE(t_lo, options.t_min);
  EXPECT_LE(t_hi, 1.0);
  // Far from the water band the transmission is constant, and the refinement keeps it.
  const cv::Mat deep = result.transmission.rowRange(kWaterRows + 2 * options.guided_radius + 2,
                                                    scene.hazy.rows);
  cv::minMaxLoc(deep, &t_lo, &t_hi);
  EXPECT_NEAR(t_lo, 0.4, 0.02);
  EXPECT_NEAR(t_hi, 0.4, 0.02);
}

TEST(DarkChannelDehazerTest, ZeroOmegaLeavesImageUnchanged) {
  cv::RNG rng(99);
  cv::Mat image(64, 80, CV_8UC3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  for (bool refine : {false, true}) {
    DehazeOptions options;
    options.omega = 0.0;
    options.refine_with_guided_filter = refine;
    const DarkChannelDehazer::Result result = DarkChannelDehazer(options).Dehaze(image);
    EXPECT_TRUE(Identical(result.image, image)) << "refine " << refine;
  }
}

TEST(DarkChannelDehazerTest, GrayImageIsOneChannel) {
  cv::Mat gray(48, 64, CV_8U);
  cv::randu(gray, 0, 256);
  const DarkChannelDehazer::Result result = DarkChannelDehazer().Dehaze(gray);
  EXPECT_EQ(result.image.type(), CV_8UC1);
  EXPECT_EQ(result.atmospheric_light[0], result.atmospheric_light[1]);
  EXPECT_EQ(result.atmospheric_light[0], result.atmospheric_light[2]);
}

TEST(DarkChannelDehazerTest, RejectsBadInput) {
  const DarkChannelDehazer dehazer;
  EXPECT_THROW(dehazer.Dehaze(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(dehazer.Dehaze(cv::Mat(8, 8, CV_16UC3, cv::Scalar::all(1))), std::invalid_argument);
  EXPECT_THROW(dehazer.Dehaze(cv::Mat(8, 8, CV_32FC3, cv::Scalar::all(1))), std::invalid_argument);
  EXPECT_THROW(dehazer.Dehaze(cv::Mat(8, 8, CV_8UC4, cv::Scalar::all(1))), std::invalid_argument);

  DehazeOptions bad;
  bad.window = 0;
  EXPECT_THROW(DarkChannelDehazer{bad}, std::invalid_argument);
  bad = DehazeOptions();
  bad.omega = 1.5;
  EXPECT_THROW(DarkChannelDehazer{bad}, std::invalid_argument);
  bad = DehazeOptions();
  bad.t_min = 0.0;
  EXPECT_THROW(DarkChannelDehazer{bad}, std::invalid_argument);
  bad = DehazeOptions();
  bad.top_fraction = 0.0;
  EXPECT_THROW(DarkChannelDehazer{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
