// LearnedLightDetector with the shipped model (data/models/light_net.onnx) on scenes drawn here,
// independently of the simulator's renderer it learned from: blue LEDs (tests/testing/led_image.h)
// round a white funnel on a textured yellow-green wall, white specks that are not lights; and its
// errors (no file, not a network).
#include "auvdock/vision/learned_light_detector.h"

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/testing/led_image.h"

namespace auvdock {
namespace {

using test::AddLed;
using test::Led;

std::string ShippedModel() { return std::string(AUVDOCK_SOURCE_DIR) + "/data/models/light_net.onnx"; }

struct Scene {
  cv::Mat bgr;
  std::vector<Led> leds;
};

// size: the image (W x H); the funnel and its 8 LEDs scale with it.
Scene MakeScene(uint64_t seed, cv::Size size) {
  std::mt19937_64 rng(seed);
  const double s = size.width / 640.0;
  Scene scene;
  cv::Mat image(size, CV_32FC3);
  cv::Mat texture(size.height / 8, size.width / 8, CV_32F);
  cv::randn(texture, 0.0, 12.0);
  cv::resize(texture, texture, image.size(), 0, 0, cv::INTER_CUBIC);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const float t = texture.at<float>(y, x);
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(30.0f + t, 95.0f + t, 90.0f + t);
    }
  }
  const cv::Point centre(static_cast<int>(330 * s), static_cast<int>(250 * s));
  cv::ellipse(image, centre, cv::Size(static_cast<int>(110 * s), static_cast<int>(95 * s)), 0, 0,
              360, cv::Scalar(150, 225, 180), cv::FILLED);
  cv::line(image, centre - cv::Point(0, static_cast<int>(95 * s)),
           centre + cv::Point(0, static_cast<int>(95 * s)), cv::Scalar(40, 40, 40),
           static_cast<int>(9 * s));
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  std::uniform_real_distribution<double> ux(20, size.width - 20), uy(20, size.height - 20);
  for (int k = 0; k < 4; ++k) {  // white specks far from the ring
    cv::Point p(static_cast<int>(ux(rng)), static_cast<int>(uy(rng)));
    if (cv::norm(p - centre) < 220 * s) continue;
    cv::circle(image, p, 2, cv::Scalar(220, 235, 235), cv::FILLED);
  }
  std::uniform_real_distribution<double> jitter(-0.5, 0.5), grow(0.8, 1.3);
  for (int k = 0; k < 8; ++k) {
    const double a = 2.0 * 3.14159265358979 * (k + 0.5) / 8.0;
    Led led{Eigen::Vector2d(centre.x + 160 * s * std::cos(a) + jitter(rng),
                            centre.y + 145 * s * std::sin(a) + jitter(rng)),
            3.0 * s * grow(rng), 7.0 * s * grow(rng)};
    AddLed(led, &image);
    scene.leds.push_back(led);
  }
  cv::Mat noise(image.size(), CV_32FC3);
  cv::randn(noise, 0.0, 2.0);
  image += noise;
  image.convertTo(scene.bgr, CV_8UC3);
  return scene;
}

LearnedLightDetectorOptions Options() {
  LearnedLightDetectorOptions o;
  o.model_path = ShippedModel();
  return o;
}

// Every LED found within max_error_px by a detection with a positive-definite covariance, and at
// most max_false other detections.
void ExpectLeds(const Scene& scene, const std::vector<LightDetection>& found, double max_error_px,
                int max_false) {
  std::vector<char> used(found.size(), 0);
  for (const Led& led : scene.leds) {
    int best = -1;
    for (size_t j = 0; j < found.size(); ++j) {
      if (!used[j] &&
          (best < 0 || (found[j].uv - led.uv).norm() < (found[best].uv - led.uv).norm())) {
        best = static_cast<int>(j);
      }
    }
    ASSERT_GE(best, 0) << "LED at " << led.uv.transpose() << " not found";
    EXPECT_LT((found[best].uv - led.uv).norm(), max_error_px) << "LED at " << led.uv.transpose();
    used[best] = 1;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(found[best].covariance);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    EXPECT_GT(found[best].score, 0.0);
    EXPECT_LE(found[best].score, 1.0);
  }
  int false_detections = 0;
  for (size_t j = 0; j < found.size(); ++j) false_detections += !used[j];
  EXPECT_LE(false_detections, max_false);
}

TEST(LearnedLightDetector, FindsLedsItNeverSawRoundAWhiteFunnel) {
  const LearnedLightDetector detector(Options());
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    const Scene scene = MakeScene(seed, cv::Size(640, 512));
    ExpectLeds(scene, detector.Detect(scene.bgr), 0.5, 1);
  }
}

TEST(LearnedLightDetector, AnyImageSizeMapsBackToItsPixels) {
  // 720 x 576 (the network sees it at 0.44) and 1280 x 1024 (at 0.25): the centres are measured
  // in the image's own pixels.
  const LearnedLightDetector detector(Options());
  for (const cv::Size size : {cv::Size(720, 576), cv::Size(1280, 1024)}) {
    const Scene scene = MakeScene(7, size);
    ExpectLeds(scene, detector.Detect(scene.bgr), 0.5 * size.width / 640.0, 1);
  }
}

TEST(LearnedLightDetector, CutByTheBorderIsFlaggedAndWidened) {
  const LearnedLightDetector detector(Options());
  cv::Mat image(512, 640, CV_32FC3, cv::Scalar(30, 90, 85));
  const Led inside{Eigen::Vector2d(320.3, 250.6), 3.0, 7.0};
  const Led border{Eigen::Vector2d(4.2, 300.4), 3.0, 7.0};
  AddLed(inside, &image);
  AddLed(border, &image);
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);
  const std::vector<LightDetection> found = detector.Detect(bgr);
  const LightDetection* a = nullptr;
  const LightDetection* b = nullptr;
  for (const LightDetection& d : found) {
    if ((d.uv - inside.uv).norm() < 1.0) a = &d;
    if ((d.uv - border.uv).norm() < 3.0) b = &d;
  }
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_FALSE(a->at_border);
  EXPECT_TRUE(b->at_border);
  EXPECT_GT(b->covariance.trace(), a->covariance.trace());
}

TEST(LearnedLightDetector, GrayImagesAndDeterminism) {
  const LearnedLightDetector detector(Options());
  const Scene scene = MakeScene(3, cv::Size(640, 512));
  const auto first = detector.Detect(scene.bgr);
  const auto again = detector.Detect(scene.bgr);
  ASSERT_EQ(first.size(), again.size());
  for (size_t k = 0; k < first.size(); ++k) EXPECT_EQ(first[k].uv, again[k].uv);
  cv::Mat gray;
  cv::cvtColor(scene.bgr, gray, cv::COLOR_BGR2GRAY);
  EXPECT_NO_THROW(detector.Detect(gray));
  EXPECT_THROW(detector.Detect(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(detector.Detect(cv::Mat(10, 10, CV_32FC3)), std::invalid_argument);
}

TEST(LearnedLightDetector, BadModelFilesNameTheFile) {
  LearnedLightDetectorOptions options;
  options.model_path = "/nonexistent/light_net.onnx";
  try {
    LearnedLightDetector detector(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/light_net.onnx"), std::string::npos);
  }
  const std::string text = testing::TempDir() + "/not_a_network.onnx";
  std::ofstream(text) << "this is not a network\n";
  options.model_path = text;
  try {
    LearnedLightDetector detector(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos);
  }
  options = Options();
  options.min_probability = 1.5;
  EXPECT_THROW(LearnedLightDetector{options}, std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
