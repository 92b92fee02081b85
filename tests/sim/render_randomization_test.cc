// The renderer's domain randomisation (sim/render_look.h, sim/image_degradation.h): the default
// look is the un-randomised renderer, looks are seeded, every degradation keeps a light's ground
// truth where it is (or, for the asymmetric lobe, biases it by the drawn amount), and the strong
// lens distortion stays monotonic over the image.
#include "auvdock/sim/render_look.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/sim/image_degradation.h"
#include "auvdock/sim/underwater_renderer.h"
#include "tests/testing/render_fixture.h"

namespace auvdock {
namespace {

RenderOptions CleanOptions() {
  RenderOptions options;
  options.noise_sigma = 0.0;
  options.reflections = false;
  options.particles_per_frame = 0.0;
  options.lamp_power = 0.0;
  options.ambient_light = 0.0;
  options.vignetting = 0.0;
  return options;
}

// Intensity centroid of |a - b| summed over the channels, in a disc around centre.
Eigen::Vector2d DifferenceCentroid(const cv::Mat& a, const cv::Mat& b,
                                   const Eigen::Vector2d& centre, double radius) {
  double sum = 0.0, su = 0.0, sv = 0.0;
  for (int v = 0; v < a.rows; ++v) {
    for (int u = 0; u < a.cols; ++u) {
      if ((Eigen::Vector2d(u, v) - centre).norm() > radius) continue;
      double w = 0.0;
      for (int ch = 0; ch < 3; ++ch) {
        w += std::fabs(static_cast<double>(a.at<cv::Vec3b>(v, u)[ch]) - b.at<cv::Vec3b>(v, u)[ch]);
      }
      sum += w, su += w * u, sv += w * v;
    }
  }
  return Eigen::Vector2d(su / sum, sv / sum);
}

bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

TEST(RenderLook, TheDefaultLookIsTheUnrandomisedRenderer) {
  const CameraCalibration camera = test::MakeRigCamera();
  const DockModel dock = test::MakeTDock();
  const WaterModel water = WaterModel::ForType(WaterType::kCoastal);
  const RenderOptions options;  // noise, reflections, particles on
  std::mt19937_64 look_rng(7);
  const RenderLook off = DrawRenderLook(RenderRandomization{}, dock, look_rng);
  EXPECT_EQ(look_rng(), std::mt19937_64(7)());  // disabled: no draw
  const UnderwaterRenderer plain(camera, dock, water, options);
  const UnderwaterRenderer with_look(camera, dock, water, options, off);
  std::mt19937_64 a(3), b(3);
  const Pose3 T_D_C = test::ApproachPose(4.0, 40.0);
  EXPECT_TRUE(SameImage(plain.Render(T_D_C, a).image, with_look.Render(T_D_C, b).image));
}

TEST(RenderLook, TheLightColourFollowsTheDockIncludingItsAliases) {
  DockModel dock = test::MakeTDock();
  dock.light_colour = "cyan";  // an alias of blue_green that dock.yaml accepts
  EXPECT_EQ(DefaultRenderLook(dock).light_colour_bgr, LightColourBgr(LightColour::kBlueGreen));
  dock.light_colour = "blue";
  const Eigen::Vector3d blue = DefaultRenderLook(dock).light_colour_bgr;
  EXPECT_GT(blue[0], blue[2]);
}

TEST(RenderLook, LooksAreSeededAndDiffer) {
  const DockModel dock = test::MakeTDock();
  RenderRandomization on;
  on.enabled = true;
  std::mt19937_64 a(11), b(11), c(12);
  const RenderLook la = DrawRenderLook(on, dock, a), lb = DrawRenderLook(on, dock, b);
  const RenderLook lc = DrawRenderLook(on, dock, c);
  EXPECT_EQ(la.light_colour_bgr, lb.light_colour_bgr);
  EXPECT_EQ(la.deck_features.size(), lb.deck_features.size());
  EXPECT_NE(la.light_size_scale, lc.light_size_scale);
  EXPECT_EQ(la.lobes.size(), dock.lights.size());
  for (const LightLobe& lobe : la.lobes) {
    EXPECT_GE(lobe.bias_px, 0.1);
    EXPECT_LE(lobe.bias_px, 0.3);
    EXPECT_NEAR(lobe.tilt_D.norm(), 1.0, 1e-12);
  }
  // The fittings keep clear of the lights; the funnel keeps 5 light radii clear, or its rim runs
  // through the lights (centred among them, its radius 0.85-1.05 of their median distance from
  // it); over seeds, both.
  int clear = 0, through = 0;
  for (uint64_t seed = 11; seed < 31; ++seed) {
    std::mt19937_64 rng(seed);
    const RenderLook look = DrawRenderLook(on, dock, rng);
    for (const DeckFeature& f : look.deck_features) {
      if (f.name != "fitting" && f.name != "funnel") continue;
      std::vector<double> gaps;
      for (const DockLight& light : dock.lights) gaps.push_back((light.p_D.head<2>() - f.a).norm());
      if (f.name == "fitting") {
        for (const double gap : gaps) EXPECT_GE(gap, 0.15);
        continue;
      }
      std::sort(gaps.begin(), gaps.end());
      if (gaps.front() >= f.radius_m + 5.0 * dock.lights.front().radius_m - 1e-9) {
        ++clear;
      } else {
        ++through;
        const double median = gaps[gaps.size() / 2];
        EXPECT_GE(f.radius_m, 0.85 * median - 1e-9);
        EXPECT_LE(f.radius_m, 1.05 * median + 1e-9);
      }
    }
  }
  EXPECT_GT(clear, 0);
  EXPECT_GT(through, 0);
  // Switching an effect off leaves its default.
  on.asymmetric_lobes = false;
  on.jpeg = false;
  std::mt19937_64 d(11);
  const RenderLook ld = DrawRenderLook(on, dock, d);
  EXPECT_TRUE(ld.lobes.empty());
  EXPECT_EQ(ld.jpeg_quality_max, 0);
}

TEST(RenderLook, TheLobeBiasesTheCentroidByTheDrawnAmountTowardsTheTilt) {
  const CameraCalibration camera = test::MakeRigCamera();
  DockModel dock = test::MakeTDock();
  for (DockLight& light : dock.lights) light.intensity = light.id == 1 ? 0.05 : 0.0;
  const WaterModel water = WaterModel::ForType(WaterType::kClear);
  const Pose3 T_D_C = test::ApproachPose(3.0, 40.0);
  RenderLook look = DefaultRenderLook(dock);
  LightLobe lobe;
  lobe.light_id = 1;
  lobe.tilt_D = Eigen::Vector3d(0.0, 1.0, 0.0);
  lobe.amplitude_fraction = 0.3;
  lobe.bias_px = 0.3;
  look.lobes.push_back(lobe);
  DockModel dark = dock;
  for (DockLight& light : dark.lights) light.intensity = 0.0;
  const UnderwaterRenderer plain(camera, dock, water, CleanOptions());
  const UnderwaterRenderer lobed(camera, dock, water, CleanOptions(), look);
  const UnderwaterRenderer off(camera, dark, water, CleanOptions());
  std::mt19937_64 rng(1);
  const RenderResult a = plain.Render(T_D_C, rng);
  const RenderResult b = lobed.Render(T_D_C, rng);
  const cv::Mat background = off.Render(T_D_C, rng).image;
  ASSERT_EQ(a.lights.size(), 1u);
  ASSERT_LT(a.lights[0].peak, 200.0);  // unsaturated: the centroid moves by the whole bias
  const Eigen::Vector2d uv = a.lights[0].uv;
  const double radius = 6.0 * a.lights[0].radius_px + 3.0;
  const Eigen::Vector2d c_plain = DifferenceCentroid(a.image, background, uv, radius);
  const Eigen::Vector2d c_lobed = DifferenceCentroid(b.image, background, uv, radius);
  EXPECT_LT((c_plain - uv).norm(), 0.05);
  const Eigen::Vector2d shift = c_lobed - c_plain;
  // The view factor is in [0.3, 1]; the direction is the image of +y of D.
  EXPECT_GT(shift.norm(), 0.3 * 0.3 - 0.03);
  EXPECT_LT(shift.norm(), 0.3 + 0.03);
  const auto tip =
      camera.intrinsics.Project(T_D_C.Inverse() * (dock.lights[1].p_D + 0.01 * lobe.tilt_D));
  ASSERT_TRUE(tip.has_value());
  EXPECT_GT(shift.normalized().dot((*tip - uv).normalized()), 0.95);
}

TEST(ImageDegradation, MotionBlurKernelIsNormalisedAndCentred) {
  for (const double length : {0.5, 2.0, 3.7}) {
    for (const double angle : {0.0, 0.4, 1.9}) {
      const cv::Mat k = MotionBlurKernel(length, angle);
      ASSERT_EQ(k.rows % 2, 1);
      double sum = 0.0, mu = 0.0, mv = 0.0;
      const double c = (k.rows - 1) / 2.0;
      for (int v = 0; v < k.rows; ++v) {
        for (int u = 0; u < k.cols; ++u) {
          const double w = k.at<float>(v, u);
          EXPECT_GE(w, 0.0);
          sum += w, mu += w * (u - c), mv += w * (v - c);
        }
      }
      EXPECT_NEAR(sum, 1.0, 1e-5);
      EXPECT_NEAR(mu, 0.0, 1e-5) << length << " " << angle;
      EXPECT_NEAR(mv, 0.0, 1e-5) << length << " " << angle;
    }
  }
}

TEST(ImageDegradation, BlurAndInterlacingKeepABlobsCentroid) {
  cv::Mat image(96, 96, CV_32FC3, cv::Scalar(20, 20, 20));
  const Eigen::Vector2d centre(47.3, 45.8);
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const double w = 150.0 * std::exp(-(Eigen::Vector2d(u, v) - centre).squaredNorm() / 8.0);
      image.at<cv::Vec3f>(v, u) += cv::Vec3f(w, w, w);
    }
  }
  RenderLook look;
  look.defocus_sigma_px = 1.0;
  look.max_motion_blur_px = 4.0;
  look.interlaced = true;
  look.field_offset_sigma_px = 0.8;
  FrameDegradation frame;
  frame.motion_blur_px = 3.5;
  frame.motion_blur_angle_rad = 0.7;
  frame.field_offset_px = Eigen::Vector2d(1.3, -0.6);
  ApplyOpticsAndFields(look, frame, &image);
  double sum = 0.0, su = 0.0, sv = 0.0;
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const double w = image.at<cv::Vec3f>(v, u)[1] - 20.0;
      sum += w, su += w * u, sv += w * v;
    }
  }
  EXPECT_NEAR(su / sum, centre.x(), 0.02);
  EXPECT_NEAR(sv / sum, centre.y(), 0.02);
  // Interlacing combs: even and odd rows now differ where the blob is.
  EXPECT_GT(cv::norm(image.row(46), image.row(47), cv::NORM_L1), 10.0);
}

TEST(ImageDegradation, PerFrameDrawsAndJpeg) {
  std::mt19937_64 rng(5);
  const FrameDegradation none = DrawFrameDegradation(RenderLook{}, rng);
  EXPECT_EQ(rng(), [] { std::mt19937_64 r(5); return r(); }());  // the default look draws nothing
  EXPECT_EQ(none.jpeg_quality, 0);
  RenderLook look;
  look.jpeg_quality_min = 45;
  look.jpeg_quality_max = 95;
  for (int i = 0; i < 50; ++i) {
    const FrameDegradation f = DrawFrameDegradation(look, rng);
    EXPECT_GE(f.jpeg_quality, 45);
    EXPECT_LE(f.jpeg_quality, 95);
  }
  cv::Mat image(64, 64, CV_8UC3);
  cv::randu(image, 60, 200);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  EXPECT_TRUE(SameImage(ApplyJpeg(none, image), image));
  FrameDegradation q90;
  q90.jpeg_quality = 90;
  const cv::Mat jpeg = ApplyJpeg(q90, image);
  ASSERT_EQ(jpeg.size(), image.size());
  EXPECT_FALSE(SameImage(jpeg, image));
  EXPECT_LT(cv::norm(jpeg, image, cv::NORM_L1) / image.total() / 3.0, 3.0);
}

TEST(RenderLook, StrongDistortionIsMonotonicToTheCorner) {
  std::mt19937_64 rng(9);
  for (int i = 0; i < 200; ++i) {
    const std::array<double, 5> d = DrawStrongDistortion(0.86, rng);
    EXPECT_LE(d[0], -0.1);
    // Along r until the distorted radius reaches the corner (0.86), the mapping keeps growing:
    // every pixel out to the corner is the image of one ray, none lies beyond the fold.
    double r = 0.0;
    for (; r < 3.0; r += 0.005) {
      const double r2 = r * r;
      if (r * (1.0 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2) >= 0.86) break;
      EXPECT_GT(1.0 + 3.0 * d[0] * r2 + 5.0 * d[1] * r2 * r2 + 7.0 * d[4] * r2 * r2 * r2, 0.19);
    }
    EXPECT_LT(r, 3.0) << "the corner is never reached";
    const PinholeRadtanCamera lens(640, 512, 400.0, 400.0, 319.5, 255.5, d);
    EXPECT_GT(lens.fold_radius(), r);
  }
}

}  // namespace
}  // namespace auvdock
