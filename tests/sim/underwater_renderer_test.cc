#include "auvdock/sim/underwater_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "auvdock/sim/water_model.h"
#include "tests/testing/render_fixture.h"

namespace auvdock {
namespace {

constexpr WaterType kAllWaterTypes[] = {WaterType::kClear, WaterType::kCoastal, WaterType::kTurbid};

RenderOptions CleanOptions() {
  RenderOptions options;
  options.noise_sigma = 0.0;
  options.reflections = false;
  options.particles_per_frame = 0.0;
  return options;
}

// The idealised scene for the centroid checks: no lamp, no daylight on the bottom, no
// vignetting; the background is the smooth veiling light alone. The centroid tests run on it and
// on the lamp-lit scene (CleanOptions): there a saturated core sits over a background that
// changes across it (the difference is 255 - background in the core), which the dark light
// housings and the soft-knee scene response keep small enough.
RenderOptions FlatBackgroundOptions() {
  RenderOptions options = CleanOptions();
  options.lamp_power = 0.0;
  options.ambient_light = 0.0;
  options.vignetting = 0.0;
  return options;
}

struct BackgroundCase {
  const char* name;
  RenderOptions options;
};

std::vector<BackgroundCase> CentroidBackgrounds() {
  return {{"lamp_lit", CleanOptions()}, {"flat", FlatBackgroundOptions()}};
}

// The dock with every light switched off (intensity 0) except the one with id `on` (-1: none).
// The lights' housings stay, so "lights off" differs from "lights on" by the light blobs only.
DockModel LightsOffExcept(const DockModel& dock, int on) {
  DockModel copy = dock;
  for (DockLight& light : copy.lights) {
    if (light.id != on) light.intensity = 0.0;
  }
  return copy;
}

// Intensity centroid of (image - background), summed over the channels, in a disc of the given
// radius around centre. Returns false when the disc leaves the image or holds no signal.
bool DifferenceCentroid(const cv::Mat& image, const cv::Mat& background,
                        const Eigen::Vector2d& centre, double radius, Eigen::Vector2d* centroid,
                        double* max_difference = nullptr) {
  const int u0 = static_cast<int>(std::floor(centre.x() - radius));
  const int u1 = static_cast<int>(std::ceil(centre.x() + radius));
  const int v0 = static_cast<int>(std::floor(centre.y() - radius));
  const int v1 = static_cast<int>(std::ceil(centre.y() + radius));
  if (u0 < 0 || v0 < 0 || u1 >= image.cols || v1 >= image.rows) return false;
  double sum = 0.0, sum_u = 0.0, sum_v = 0.0, max_seen = 0.0;
  for (int v = v0; v <= v1; ++v) {
    const cv::Vec3b* row = image.ptr<cv::Vec3b>(v);
    const cv::Vec3b* row_bg = background.ptr<cv::Vec3b>(v);
    for (int u = u0; u <= u1; ++u) {
      if ((u - centre.x()) * (u - centre.x()) + (v - centre.y()) * (v - centre.y()) >
          radius * radius) {
        continue;
      }
      double w = 0.0;
      for (int ch = 0; ch < 3; ++ch) w += static_cast<double>(row[u][ch]) - row_bg[u][ch];
      max_seen = std::max(max_seen, w);
      sum += w;
      sum_u += w * u;
      sum_v += w * v;
    }
  }
  if (max_difference != nullptr) *max_difference = max_seen;
  if (!(sum > 0.0)) return false;
  *centroid = Eigen::Vector2d(sum_u / sum, sum_v / sum);
  return true;
}

struct PoseCase {
  const char* name;
  Pose3 T_D_C;
};

std::vector<PoseCase> CentroidPoses() {
  std::vector<PoseCase> poses;
  for (double range : {2.0, 4.0, 6.0, 8.0}) {
    poses.push_back({"forward_down_40", test::ApproachPose(range, 40.0)});
    poses.push_back({"straight_down", test::ApproachPose(range, 90.0)});
  }
  // Off the axis and yawed: the lights land off the image centre, where distortion and
  // vignetting are strongest.
  poses.push_back({"oblique_offset", test::LookAt(Eigen::Vector3d(-3.0, 2.0, -2.5),
                                                  Eigen::Vector3d(0.8, -0.6, 0.0))});
  return poses;
}

TEST(WaterModelTest, NamesRoundTrip) {
  for (WaterType type : kAllWaterTypes) {
    WaterType parsed = WaterType::kClear;
    ASSERT_TRUE(ParseWaterType(WaterTypeName(type), &parsed));
    EXPECT_EQ(parsed, type);
  }
  WaterType parsed = WaterType::kCoastal;
  EXPECT_FALSE(ParseWaterType("murky", &parsed));
  EXPECT_FALSE(ParseWaterType("", &parsed));
  EXPECT_EQ(parsed, WaterType::kCoastal);
}

TEST(WaterModelTest, TransmissionIsBeerLambert) {
  const WaterModel water = WaterModel::ForType(WaterType::kCoastal);
  EXPECT_TRUE(water.Transmission(0.0).isApprox(Eigen::Vector3d::Ones()));
  const Eigen::Vector3d t = water.Transmission(3.0);
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_NEAR(t[ch], std::exp(-3.0 * water.attenuation_per_m[ch]), 1e-12);
  }
  // Multiplicative over path segments.
  EXPECT_TRUE(water.Transmission(5.0).isApprox(
      water.Transmission(2.0).cwiseProduct(water.Transmission(3.0))));
}

TEST(WaterModelTest, TypesArePhysicallyOrdered) {
  const WaterModel clear = WaterModel::ForType(WaterType::kClear);
  const WaterModel coastal = WaterModel::ForType(WaterType::kCoastal);
  const WaterModel turbid = WaterModel::ForType(WaterType::kTurbid);
  // Red is attenuated most in clear water; green least in coastal and turbid water.
  EXPECT_GT(clear.attenuation_per_m[2], clear.attenuation_per_m[1]);
  EXPECT_GT(clear.attenuation_per_m[1], clear.attenuation_per_m[0]);
  for (const WaterModel* water : {&coastal, &turbid}) {
    EXPECT_LT(water->attenuation_per_m[1], water->attenuation_per_m[0]);
    EXPECT_LT(water->attenuation_per_m[1], water->attenuation_per_m[2]);
  }
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_LT(clear.attenuation_per_m[ch], coastal.attenuation_per_m[ch]);
    EXPECT_LT(coastal.attenuation_per_m[ch], turbid.attenuation_per_m[ch]);
  }
  for (const WaterModel* water : {&clear, &coastal, &turbid}) {
    EXPECT_GE(water->veiling_light.minCoeff(), 0.0);
    EXPECT_LE(water->veiling_light.maxCoeff(), 1.0);
  }
}

// The core accuracy property: with noise off, every light's blob has its intensity centroid on
// the light's projection through the camera model. A light whose window would hold part of a
// neighbouring blob is rendered again alone (the others switched off).
TEST(UnderwaterRendererTest, LightCentroidsMatchProjection) {
  const CameraCalibration camera = test::MakeRigCamera();
  const DockModel dock = test::MakeTDock();
  const std::vector<PoseCase> poses = CentroidPoses();
  for (const BackgroundCase& background_case : CentroidBackgrounds()) {
    SCOPED_TRACE(background_case.name);
    for (WaterType type : kAllWaterTypes) {
      SCOPED_TRACE(WaterTypeName(type));
      const WaterModel water = WaterModel::ForType(type);
      const RenderOptions& options = background_case.options;
      const UnderwaterRenderer full(camera, dock, water, options);
      const UnderwaterRenderer lights_off(camera, LightsOffExcept(dock, -1), water, options);
      std::vector<std::unique_ptr<UnderwaterRenderer>> single(dock.lights.size());
      int checked = 0, checked_on_full_dock = 0;
      double worst_error = 0.0;
      for (const PoseCase& pose : poses) {
        SCOPED_TRACE(pose.name);
        std::mt19937_64 rng(1);
        const RenderResult result = full.Render(pose.T_D_C, rng);
        const cv::Mat background = lights_off.Render(pose.T_D_C, rng).image;
        for (const RenderedLight& light : result.lights) {
          SCOPED_TRACE("light " + std::to_string(light.light_id) + " at " +
                       std::to_string(light.range_m) + " m");
          const auto projection =
              camera.intrinsics.Project(pose.T_D_C.Inverse() * dock.lights[light.light_id].p_D);
          ASSERT_TRUE(projection.has_value());
          EXPECT_LT((light.uv - *projection).norm(), 1e-9);
          const double window = 5.0 * light.radius_px + 2.0;
          bool separated = true;
          for (const RenderedLight& other : result.lights) {
            if (other.light_id != light.light_id &&
                (other.uv - light.uv).norm() < window + 5.0 * other.radius_px) {
              separated = false;
            }
          }
          cv::Mat image = result.image;
          if (!separated) {
            auto& alone = single[light.light_id];
            if (!alone) {
              alone = std::make_unique<UnderwaterRenderer>(
                  camera, LightsOffExcept(dock, light.light_id), water, options);
            }
            const RenderResult rendered = alone->Render(pose.T_D_C, rng);
            ASSERT_EQ(rendered.lights.size(), 1u);
            image = rendered.image;
          }
          Eigen::Vector2d centroid;
          if (!DifferenceCentroid(image, background, *projection, window, &centroid)) {
            continue;  // window leaves the image
          }
          const double error = (centroid - *projection).norm();
          worst_error = std::max(worst_error, error);
          EXPECT_LT(error, 0.2) << "peak " << light.peak << " sigma " << light.radius_px;
          ++checked;
          checked_on_full_dock += separated ? 1 : 0;
        }
      }
      // Turbid water hides the lights of the 6 m and 8 m views.
      EXPECT_GE(checked, type == WaterType::kTurbid ? 25 : 40);
      EXPECT_GE(checked_on_full_dock, 5);
      RecordProperty(std::string("worst_centroid_error_px_") + background_case.name + "_" +
                         WaterTypeName(type),
                     std::to_string(worst_error));
    }
  }
}

TEST(UnderwaterRendererTest, SameSeedIsByteIdenticalAndDifferentSeedsDiffer) {
  const CameraCalibration camera = test::MakeRigCamera();
  RenderOptions options;  // noise, reflections and particles all on
  options.particles_per_frame = 5.0;
  const UnderwaterRenderer renderer(camera, test::MakeTDock(),
                                    WaterModel::ForType(WaterType::kCoastal), options);
  const Pose3 T_D_C = test::ApproachPose(4.0, 40.0);
  std::mt19937_64 rng_a(123), rng_b(123), rng_c(124);
  const RenderResult a = renderer.Render(T_D_C, rng_a);
  const RenderResult b = renderer.Render(T_D_C, rng_b);
  const RenderResult c = renderer.Render(T_D_C, rng_c);
  ASSERT_EQ(a.image.type(), CV_8UC3);
  ASSERT_EQ(a.image.cols, 640);
  ASSERT_EQ(a.image.rows, 512);
  ASSERT_TRUE(a.image.isContinuous() && b.image.isContinuous());
  EXPECT_EQ(std::memcmp(a.image.data, b.image.data, a.image.total() * a.image.elemSize()), 0);
  ASSERT_EQ(a.distractors.size(), b.distractors.size());
  for (size_t i = 0; i < a.distractors.size(); ++i) {
    EXPECT_EQ(a.distractors[i].kind, b.distractors[i].kind);
    EXPECT_EQ(a.distractors[i].uv, b.distractors[i].uv);
  }
  EXPECT_GT(cv::norm(a.image, c.image, cv::NORM_L1), 0.0);
  // The generator advanced: the next frame is a different draw.
  const RenderResult a2 = renderer.Render(T_D_C, rng_a);
  EXPECT_GT(cv::norm(a.image, a2.image, cv::NORM_L1), 0.0);
}

TEST(UnderwaterRendererTest, DistractorsAreReported) {
  const CameraCalibration camera = test::MakeRigCamera();
  RenderOptions options;
  options.particles_per_frame = 8.0;
  const UnderwaterRenderer renderer(camera, test::MakeTDock(),
                                    WaterModel::ForType(WaterType::kClear), options);
  const Pose3 T_D_C = test::ApproachPose(6.0, 60.0);
  std::mt19937_64 rng(5);
  int particles = 0, reflections = 0;
  for (int frame = 0; frame < 20; ++frame) {
    const RenderResult result = renderer.Render(T_D_C, rng);
    ASSERT_EQ(result.lights.size(), 6u);
    for (const RenderedDistractor& d : result.distractors) {
      EXPECT_TRUE(camera.intrinsics.InImage(d.uv));
      if (d.kind == "particle") {
        ++particles;
        EXPECT_GE(d.radius_px, 0.6);
        EXPECT_LE(d.radius_px, 1.5);
      } else {
        ASSERT_EQ(d.kind, "reflection");
        ++reflections;
      }
    }
  }
  EXPECT_EQ(reflections, 20 * 6);           // every light's reflection stays in the image here
  EXPECT_NEAR(particles / 20.0, 8.0, 3.0);  // Poisson mean
}

TEST(UnderwaterRendererTest, InvisibleLightsAreNotReported) {
  const CameraCalibration camera = test::MakeRigCamera();
  const DockModel dock = test::MakeTDock();
  const UnderwaterRenderer renderer(camera, dock, WaterModel::ForType(WaterType::kClear),
                                    CleanOptions());
  std::mt19937_64 rng(3);
  // Dock behind the camera: above the dock, looking up and away.
  const Pose3 looking_away =
      test::LookAt(Eigen::Vector3d(-3.0, 0.0, -3.0), Eigen::Vector3d(-10.0, 0.0, -6.0));
  EXPECT_TRUE(renderer.VisibleLights(looking_away).empty());
  EXPECT_TRUE(renderer.Render(looking_away, rng).lights.empty());
  // Dock far outside the field of view, in front of the camera.
  const Pose3 looking_aside =
      test::LookAt(Eigen::Vector3d(-4.0, 0.0, -3.0), Eigen::Vector3d(-4.0, 8.0, 0.0));
  EXPECT_TRUE(renderer.VisibleLights(looking_aside).empty());
  // Below the emission cone: a camera level with the deck sees the lights' sides.
  const Pose3 level = test::LookAt(Eigen::Vector3d(-5.0, 0.0, 0.1), Eigen::Vector3d::Zero());
  EXPECT_TRUE(renderer.VisibleLights(level).empty());
  // Part of the dock in view: exactly the lights in front and inside the image are reported.
  const Pose3 partial =
      test::LookAt(Eigen::Vector3d(-1.5, 0.0, -1.5), Eigen::Vector3d(-1.5, 1.0, 0.3));
  const std::vector<RenderedLight> visible = renderer.VisibleLights(partial);
  int expected = 0;
  for (const DockLight& light : dock.lights) {
    const auto uv = camera.intrinsics.Project(partial.Inverse() * light.p_D);
    const bool in_view = uv.has_value() && camera.intrinsics.InImage(*uv);
    expected += in_view ? 1 : 0;
    bool reported = false;
    for (const RenderedLight& r : visible) reported |= r.light_id == light.id;
    EXPECT_EQ(reported, in_view) << "light " << light.id;
  }
  EXPECT_GT(expected, 0);
  EXPECT_LT(expected, 6);
  EXPECT_EQ(renderer.Render(partial, rng).lights.size(), visible.size());
}

// A light on a mast 0.25 m above the deck sits in its own housing at its height: seen at a
// slant, the dark disc is centred on the light's image. (Drawn flush with the deck below it, the
// disc lay tens of pixels off to one side, and the edge under the light's glow biased centroids.)
TEST(UnderwaterRendererTest, ARaisedLightsHousingIsCentredOnTheLight) {
  const CameraCalibration camera = test::MakeRigCamera();
  DockModel dock = LightsOffExcept(test::MakeTDock(), -1);
  dock.lights.resize(1);
  dock.lights[0].p_D = Eigen::Vector3d(0.0, 0.0, -0.25);
  const UnderwaterRenderer renderer(camera, dock, WaterModel::ForType(WaterType::kClear),
                                    CleanOptions());
  for (double depression_deg : {35.0, 55.0, 90.0}) {
    SCOPED_TRACE(depression_deg);
    const Pose3 T_D_C = test::ApproachPose(2.5, depression_deg, dock.lights[0].p_D);
    std::mt19937_64 rng(5);
    const cv::Mat image = renderer.Render(T_D_C, rng).image;
    const auto uv = camera.intrinsics.Project(T_D_C.Inverse() * dock.lights[0].p_D);
    ASSERT_TRUE(uv.has_value());
    // The disc (radius 0.2 m) spans ~fx 0.2 / 2.5 px across; look twice as far.
    const double radius_px = camera.intrinsics.fx() * 0.2 / 2.5;
    cv::Mat grey;
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    const uint8_t centre_level = grey.at<uint8_t>(cvRound(uv->y()), cvRound(uv->x()));
    auto around = [&](auto&& visit) {
      for (int v = 0; v < grey.rows; ++v) {
        for (int u = 0; u < grey.cols; ++u) {
          const double du = u - uv->x(), dv = v - uv->y();
          if (du * du + dv * dv <= 4.0 * radius_px * radius_px) visit(u, v, grey.at<uint8_t>(v, u));
        }
      }
    };
    int brightest_around = 0;
    around([&](int, int, int level) { brightest_around = std::max(brightest_around, level); });
    EXPECT_GT(brightest_around, centre_level + 20);  // the deck around is lit
    const int cut = (centre_level + brightest_around) / 2;
    double sum = 0.0, sum_u = 0.0, sum_v = 0.0;
    around([&](int u, int v, int level) {
      if (level < cut) sum += 1.0, sum_u += u, sum_v += v;  // the housing
    });
    ASSERT_GT(sum, 0.0);
    // Perspective alone moves a slanted disc's image centroid toward its near half (1.4 px here);
    // drawn on the deck below, the disc was 7 px (35 deg) to 25 px (55 deg) off.
    EXPECT_LT(std::hypot(sum_u / sum - uv->x(), sum_v / sum - uv->y()), 2.5);
  }
}

TEST(UnderwaterRendererTest, TurbidWaterDimsTheLights) {
  const CameraCalibration camera = test::MakeRigCamera();
  const DockModel dock = test::MakeTDock();
  const Pose3 T_D_C = test::ApproachPose(4.0, 90.0);
  std::map<WaterType, std::vector<RenderedLight>> lights;
  std::map<WaterType, double> image_peak;
  for (WaterType type : kAllWaterTypes) {
    const WaterModel water = WaterModel::ForType(type);
    const UnderwaterRenderer renderer(camera, dock, water, CleanOptions());
    const UnderwaterRenderer empty(camera, LightsOffExcept(dock, -1), water, CleanOptions());
    std::mt19937_64 rng(11);
    const RenderResult result = renderer.Render(T_D_C, rng);
    const cv::Mat background = empty.Render(T_D_C, rng).image;
    lights[type] = result.lights;
    ASSERT_EQ(result.lights.size(), 6u) << WaterTypeName(type);
    Eigen::Vector2d centroid;
    double max_difference = 0.0;
    ASSERT_TRUE(DifferenceCentroid(result.image, background, result.lights[1].uv,
                                   3.0 * result.lights[1].radius_px, &centroid, &max_difference));
    image_peak[type] = max_difference;
  }
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_DOUBLE_EQ(lights[WaterType::kClear][i].range_m, lights[WaterType::kTurbid][i].range_m);
    EXPECT_GT(lights[WaterType::kClear][i].peak, lights[WaterType::kCoastal][i].peak);
    EXPECT_GT(lights[WaterType::kCoastal][i].peak, lights[WaterType::kTurbid][i].peak);
  }
  EXPECT_GT(image_peak[WaterType::kClear], image_peak[WaterType::kTurbid]);
  EXPECT_LT(lights[WaterType::kTurbid][1].peak, 255.0);  // not saturated at 4 m
}

TEST(UnderwaterRendererTest, FarLightsLookSmallerAndDimmer) {
  const CameraCalibration camera = test::MakeRigCamera();
  const UnderwaterRenderer renderer(camera, test::MakeTDock(),
                                    WaterModel::ForType(WaterType::kCoastal), CleanOptions());
  // Within one oblique view: sorted by range, radius and peak fall.
  std::vector<RenderedLight> visible = renderer.VisibleLights(test::ApproachPose(3.0, 30.0));
  ASSERT_EQ(visible.size(), 6u);
  std::sort(visible.begin(), visible.end(),
            [](const RenderedLight& a, const RenderedLight& b) { return a.range_m < b.range_m; });
  for (size_t i = 1; i < visible.size(); ++i) {
    if (visible[i].range_m > visible[i - 1].range_m + 1e-6) {
      EXPECT_LT(visible[i].radius_px, visible[i - 1].radius_px);
    }
  }
  // The same light from 2 m and from 8 m.
  const auto near = renderer.VisibleLights(test::ApproachPose(2.0, 90.0));
  const auto far = renderer.VisibleLights(test::ApproachPose(8.0, 90.0));
  ASSERT_FALSE(near.empty());
  ASSERT_FALSE(far.empty());
  ASSERT_EQ(near[0].light_id, far[0].light_id);
  EXPECT_LT(far[0].radius_px, near[0].radius_px);
  EXPECT_LT(far[0].peak, near[0].peak);
  EXPECT_NEAR(near[0].radius_px * near[0].range_m, far[0].radius_px * far[0].range_m, 1e-9);
}

// The brightness budget: close lights saturate; lights stay detectable to ~9 m in clear and
// coastal water and ~4.5 m in turbid water, and fade out beyond.
TEST(UnderwaterRendererTest, DetectionRangesMatchTheWaterTypes) {
  const CameraCalibration camera = test::MakeRigCamera();
  const DockModel dock = test::MakeTDock();
  auto visible_count = [&](WaterType type, double range) {
    const UnderwaterRenderer renderer(camera, dock, WaterModel::ForType(type), CleanOptions());
    return renderer.VisibleLights(test::ApproachPose(range, 90.0)).size();
  };
  EXPECT_EQ(visible_count(WaterType::kClear, 9.5), 6u);
  EXPECT_EQ(visible_count(WaterType::kCoastal, 9.5), 6u);
  EXPECT_EQ(visible_count(WaterType::kTurbid, 4.5), 6u);
  EXPECT_EQ(visible_count(WaterType::kTurbid, 9.0), 0u);
  EXPECT_EQ(visible_count(WaterType::kCoastal, 25.0), 0u);
  const UnderwaterRenderer clear(camera, dock, WaterModel::ForType(WaterType::kClear),
                                 CleanOptions());
  for (const RenderedLight& light : clear.VisibleLights(test::ApproachPose(2.0, 90.0))) {
    EXPECT_GT(light.peak, 255.0);
  }
}

}  // namespace
}  // namespace auvdock
