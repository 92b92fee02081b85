#include "auvdock/vision/light_detector.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "auvdock/sim/underwater_renderer.h"
#include "auvdock/sim/water_model.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Adds amplitude_bgr * exp(-|x - centre|^2 / (2 sigma^2)) to a CV_32FC3 image.
void AddBlob(const Eigen::Vector2d& centre, double sigma, const cv::Vec3f& amplitude_bgr,
             cv::Mat* image) {
  for (int y = 0; y < image->rows; ++y) {
    for (int x = 0; x < image->cols; ++x) {
      const double d2 = (x - centre.x()) * (x - centre.x()) + (y - centre.y()) * (y - centre.y());
      if (d2 > 36.0 * sigma * sigma) continue;
      image->at<cv::Vec3f>(y, x) += amplitude_bgr * static_cast<float>(std::exp(-d2 / (2 * sigma * sigma)));
    }
  }
}

cv::Mat ToEightBit(const cv::Mat& image, double noise_sigma, uint64_t seed) {
  cv::Mat noisy = image.clone();
  if (noise_sigma > 0.0) {
    cv::Mat noise(image.size(), CV_32FC3);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    noisy += noise;
  }
  cv::Mat out;
  noisy.convertTo(out, CV_8UC3);
  return out;
}

TEST(LightDetectorTest, RejectsBadInput) {
  const LightDetector detector;
  EXPECT_THROW(detector.Detect(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(detector.Detect(cv::Mat(32, 32, CV_16UC3, cv::Scalar::all(0))),
               std::invalid_argument);
  EXPECT_THROW(detector.Detect(cv::Mat(32, 32, CV_32FC1, cv::Scalar::all(0))),
               std::invalid_argument);
  EXPECT_THROW(detector.Detect(cv::Mat(32, 32, CV_8UC4, cv::Scalar::all(0))),
               std::invalid_argument);
}

TEST(LightDetectorTest, BlackImageHasNoLights) {
  const LightDetector detector;
  EXPECT_TRUE(detector.Detect(cv::Mat::zeros(512, 640, CV_8UC3)).empty());
  EXPECT_TRUE(detector.Detect(cv::Mat::zeros(128, 160, CV_8UC1)).empty());
}

TEST(LightDetectorTest, FindsAnIsolatedLightAtItsCentre) {
  // A blue-green light on a hazy gradient, with noise: sub-pixel position, radius and peak.
  cv::Mat scene(240, 320, CV_32FC3);
  for (int y = 0; y < scene.rows; ++y) {
    for (int x = 0; x < scene.cols; ++x) {
      scene.at<cv::Vec3f>(y, x) = cv::Vec3f(60.0f + 0.1f * x, 50.0f + 0.05f * y, 10.0f);
    }
  }
  const Eigen::Vector2d centre(151.37, 97.81);
  AddBlob(centre, 4.0, cv::Vec3f(85.0f, 100.0f, 20.0f), &scene);
  const std::vector<LightDetection> lights = LightDetector().Detect(ToEightBit(scene, 2.0, 1));
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_LT((lights[0].uv - centre).norm(), 0.1);
  EXPECT_GT(lights[0].radius_px, 4.0);
  EXPECT_NEAR(lights[0].peak, 160.0, 8.0);
  EXPECT_GT(lights[0].score, 0.0);
  EXPECT_LE(lights[0].score, 1.0);
}

TEST(LightDetectorTest, RejectsAParticleAndAReflection) {
  cv::Mat scene(240, 320, CV_32FC3, cv::Scalar(40.0, 35.0, 10.0));
  const Eigen::Vector2d light(100.2, 80.6);
  AddBlob(light, 5.0, cv::Vec3f(300.0f, 350.0f, 70.0f), &scene);  // clipped blue-green light
  // Its reflection: 3 sigma + 3 px below, 1.6 times as wide, a fifth as bright.
  AddBlob(light + Eigen::Vector2d(0.5, 18.0), 8.0, cv::Vec3f(60.0f, 70.0f, 14.0f), &scene);
  // A white speck of marine snow.
  AddBlob(Eigen::Vector2d(230.4, 150.2), 1.0, cv::Vec3f(150.0f, 150.0f, 130.0f), &scene);
  const std::vector<LightDetection> lights = LightDetector().Detect(ToEightBit(scene, 2.0, 2));
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_LT((lights[0].uv - light).norm(), 0.5);

  LightDetectorOptions keep_all;
  keep_all.reject_reflections = false;
  keep_all.reject_particles = false;
  EXPECT_GT(LightDetector(keep_all).Detect(ToEightBit(scene, 2.0, 2)).size(), 1u);
}

TEST(LightDetectorTest, SortsByDescendingScore) {
  cv::Mat scene(240, 320, CV_32FC3, cv::Scalar(30.0, 30.0, 8.0));
  AddBlob(Eigen::Vector2d(60.3, 60.7), 3.0, cv::Vec3f(25.0f, 30.0f, 5.0f), &scene);
  AddBlob(Eigen::Vector2d(200.6, 120.2), 4.0, cv::Vec3f(150.0f, 180.0f, 35.0f), &scene);
  AddBlob(Eigen::Vector2d(120.1, 180.9), 3.5, cv::Vec3f(60.0f, 70.0f, 12.0f), &scene);
  const std::vector<LightDetection> lights = LightDetector().Detect(ToEightBit(scene, 2.0, 3));
  ASSERT_EQ(lights.size(), 3u);
  for (size_t i = 1; i < lights.size(); ++i) EXPECT_GE(lights[i - 1].score, lights[i].score);
}

// Detection quality along the default docking run, rendered by the simulator: every 4th frame
// of the 40 s run (100 frames) for each of the three cameras, in clear and in turbid water, with
// reflections, marine snow (3 particles per frame on average) and sensor noise on.
//
// Ground truth is RenderResult::lights. A rendered light within 2 px of a detection is found. The
// recall counts the lights nearer than 8 m; the precision counts every detection that is within
// 2 px of a light nearer than 8 m as right and every detection within 2 px of no light at all as
// wrong (a detection of a light beyond 8 m is neither). The centroid RMS is over the found lights
// nearer than 8 m.
//
// A light is left out of the recall when the image cannot show it: when more than a quarter of
// the circle at 2 sigma around it is clipped white in every channel, its blob merges into a
// white-out (an over-exposed close-up of the lamp-lit deck). The number left out is printed; with
// the renderer's exposure it is expected to be 0.
struct QualityFigures {
  int lights = 0;        // rendered lights nearer than 8 m that the image can show
  int left_out = 0;      // nearer than 8 m but inside a white-out
  int found = 0;
  int right = 0;         // detections on a light nearer than 8 m
  int wrong = 0;         // detections on no light
  double squared_error = 0.0;
  double Recall() const { return lights > 0 ? static_cast<double>(found) / lights : 0.0; }
  double Precision() const {
    return right + wrong > 0 ? static_cast<double>(right) / (right + wrong) : 0.0;
  }
  double Rms() const { return found > 0 ? std::sqrt(squared_error / found) : 0.0; }
};

bool InWhiteOut(const cv::Mat& image, const RenderedLight& light) {
  int inside = 0, white = 0;
  for (int k = 0; k < 64; ++k) {
    const double angle = 2.0 * kPi * k / 64.0;
    const int u = static_cast<int>(std::lround(light.uv.x() + 2.0 * light.radius_px * std::cos(angle)));
    const int v = static_cast<int>(std::lround(light.uv.y() + 2.0 * light.radius_px * std::sin(angle)));
    if (u < 0 || v < 0 || u >= image.cols || v >= image.rows) continue;
    ++inside;
    const cv::Vec3b& p = image.at<cv::Vec3b>(v, u);
    if (p[0] >= 254 && p[1] >= 254 && p[2] >= 254) ++white;
  }
  return inside > 0 && 4 * white > inside;
}

QualityFigures MeasureAlongDockingRun(WaterType water) {
  constexpr double kMaxRangeM = 8.0;
  constexpr double kMatchPx = 2.0;
  constexpr int kFrameStep = 4;
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  RenderOptions render = scenario.render;
  render.reflections = true;
  render.particles_per_frame = std::max(3.0, render.particles_per_frame);
  render.noise_sigma = std::max(2.0, render.noise_sigma);
  const LightDetector detector;

  QualityFigures figures;
  for (size_t camera_index = 0; camera_index < calibration.cameras.size(); ++camera_index) {
    const CameraCalibration& camera = calibration.cameras[camera_index];
    const UnderwaterRenderer renderer(camera, scenario.dock, WaterModel::ForType(water), render);
    std::mt19937_64 rng(20250 + 17 * camera_index + static_cast<int>(water));
    const int frames = static_cast<int>(scenario.duration_s * camera.rate_hz);
    for (int frame = 0; frame < frames; frame += kFrameStep) {
      const double t = frame / camera.rate_hz;
      const RenderResult result = renderer.Render(trajectory.At(t).T_D_B * camera.T_B_C, rng);
      const std::vector<LightDetection> detections = detector.Detect(result.image);

      for (const RenderedLight& light : result.lights) {
        if (light.range_m >= kMaxRangeM) continue;
        if (InWhiteOut(result.image, light)) {
          ++figures.left_out;
          continue;
        }
        ++figures.lights;
        double nearest = kMatchPx;
        for (const LightDetection& detection : detections) {
          nearest = std::min(nearest, (detection.uv - light.uv).norm());
        }
        if (nearest < kMatchPx) {
          ++figures.found;
          figures.squared_error += nearest * nearest;
        }
      }
      for (const LightDetection& detection : detections) {
        double nearest = kMatchPx;
        const RenderedLight* match = nullptr;
        for (const RenderedLight& light : result.lights) {
          const double d = (detection.uv - light.uv).norm();
          if (d < nearest) {
            nearest = d;
            match = &light;
          }
        }
        if (match == nullptr) {
          ++figures.wrong;
        } else if (match->range_m < kMaxRangeM) {
          ++figures.right;
        }
      }
    }
  }
  return figures;
}

void Report(const std::string& water, const QualityFigures& figures) {
  std::ostringstream line;
  line << water << " water: " << figures.lights << " lights nearer than 8 m ("
       << figures.left_out << " left out in white-outs), recall " << figures.Recall()
       << ", precision " << figures.Precision() << " (" << figures.wrong
       << " wrong detections), centroid RMS " << figures.Rms() << " px";
  std::cout << line.str() << std::endl;
  ::testing::Test::RecordProperty(water + "_recall", std::to_string(figures.Recall()));
  ::testing::Test::RecordProperty(water + "_precision", std::to_string(figures.Precision()));
  ::testing::Test::RecordProperty(water + "_centroid_rms_px", std::to_string(figures.Rms()));
}

TEST(LightDetectorQualityTest, ClearWaterAlongDockingRun) {
  const QualityFigures figures = MeasureAlongDockingRun(WaterType::kClear);
  Report("clear", figures);
  ASSERT_GT(figures.lights, 500);
  EXPECT_GE(figures.Recall(), 0.99);
  EXPECT_GE(figures.Precision(), 0.99);
  EXPECT_LE(figures.Rms(), 0.3);
}

TEST(LightDetectorQualityTest, TurbidWaterAlongDockingRun) {
  const QualityFigures figures = MeasureAlongDockingRun(WaterType::kTurbid);
  Report("turbid", figures);
  ASSERT_GT(figures.lights, 400);
  EXPECT_GE(figures.Recall(), 0.99);
  EXPECT_GE(figures.Precision(), 0.99);
  EXPECT_LE(figures.Rms(), 0.3);
}

}  // namespace
}  // namespace auvdock
