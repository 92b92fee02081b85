// BlobLightDetector on scenes drawn here, independently of the simulator's renderer: blue LEDs
// (tests/testing/led_image.h) beside a large white-green funnel, white spots, a
// yellow-green textured wall, JPEG compression; and its parts (candidates, core centroid).
#include "auvdock/vision/blob_light_detector.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/vision/field_deinterlace.h"
#include "auvdock/vision/halo_colour_learner.h"
#include "tests/testing/led_image.h"

namespace auvdock {
namespace {

using test::AddLed;
using test::Led;

struct Scene {
  cv::Mat bgr;
  std::vector<Led> leds;
};

Scene MakeScene(uint64_t seed, bool jpeg) {
  std::mt19937_64 rng(seed);
  Scene scene;
  cv::Mat image(480, 640, CV_32FC3);
  cv::Mat texture(480 / 8, 640 / 8, CV_32F);
  cv::randn(texture, 0.0, 12.0);
  cv::resize(texture, texture, image.size(), 0, 0, cv::INTER_CUBIC);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const float t = texture.at<float>(y, x);
      const float shade = 0.6f + 0.4f * static_cast<float>(y) / image.rows;
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(30.0f + t, 95.0f + t, 90.0f + t) * shade;
    }
  }
  // A white-green funnel interior, partly saturated, with dark vanes.
  cv::ellipse(image, cv::Point(330, 250), cv::Size(120, 100), 0, 0, 360,
              cv::Scalar(150, 225, 180), cv::FILLED);
  cv::ellipse(image, cv::Point(330, 290), cv::Size(90, 45), 0, 0, 360, cv::Scalar(255, 255, 250),
              cv::FILLED);
  cv::line(image, cv::Point(330, 150), cv::Point(330, 350), cv::Scalar(40, 40, 40), 9);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 2.0);
  // White specks (fittings, marine snow) that are not lights.
  std::uniform_real_distribution<double> ux(20, 620), uy(20, 460);
  for (int k = 0; k < 6; ++k) {
    cv::circle(image, cv::Point(int(ux(rng)), int(uy(rng))), 2, cv::Scalar(220, 235, 235),
               cv::FILLED);
  }
  // Eight LEDs round the funnel, one of them touching its bright rim.
  std::uniform_real_distribution<double> jitter(-0.5, 0.5), size(0.8, 1.3);
  for (int k = 0; k < 8; ++k) {
    const double a = 2.0 * 3.14159265358979 * (k + 0.5) / 8.0;
    const double radius = k == 2 ? 118.0 : 150.0;
    Led led{Eigen::Vector2d(330 + radius * 1.1 * std::cos(a) + jitter(rng),
                            250 + radius * std::sin(a) + jitter(rng)),
            3.0 * size(rng), 7.0 * size(rng)};
    AddLed(led, &image);
    scene.leds.push_back(led);
  }
  cv::Mat noise(image.size(), CV_32FC3);
  cv::randn(noise, 0.0, 2.0);
  image += noise;
  image.convertTo(scene.bgr, CV_8UC3);
  if (jpeg) {
    std::vector<uchar> buffer;
    cv::imencode(".jpg", scene.bgr, buffer, {cv::IMWRITE_JPEG_QUALITY, 85});
    scene.bgr = cv::imdecode(buffer, cv::IMREAD_COLOR);
  }
  return scene;
}

BlobLightDetectorOptions BlueOptions() {
  BlobLightDetectorOptions o;
  o.checks.colour = LightColour::kBlue;
  return o;
}

void ExpectAllLedsAndNothingElse(const Scene& scene, const std::vector<LightDetection>& found,
                                 double max_error_px) {
  std::vector<char> used(found.size(), 0);
  for (const Led& led : scene.leds) {
    int best = -1;
    for (size_t j = 0; j < found.size(); ++j) {
      if (!used[j] && (best < 0 || (found[j].uv - led.uv).norm() < (found[best].uv - led.uv).norm())) {
        best = static_cast<int>(j);
      }
    }
    ASSERT_GE(best, 0) << "LED at " << led.uv.transpose() << " not found";
    EXPECT_LT((found[best].uv - led.uv).norm(), max_error_px) << "LED at " << led.uv.transpose();
    used[best] = 1;
  }
  for (size_t j = 0; j < found.size(); ++j) {
    EXPECT_TRUE(used[j]) << "false detection at " << found[j].uv.transpose();
  }
}

// The LEDs' ids as an identification would give them (by nearest true LED within 1 px).
std::vector<int> TrueIds(const Scene& scene, const std::vector<LightDetection>& found) {
  std::vector<int> ids(found.size(), -1);
  for (size_t j = 0; j < found.size(); ++j) {
    for (size_t k = 0; k < scene.leds.size(); ++k) {
      if ((found[j].uv - scene.leds[k].uv).norm() < 1.0) ids[j] = static_cast<int>(k);
    }
  }
  return ids;
}

// Detection as in a run: a first frame at the permissive threshold, whose identified LEDs teach
// the footage's halo colour, then the frame again at the learned threshold.
std::vector<LightDetection> DetectWithLearnedColour(const Scene& scene) {
  const BlobLightDetector detector(BlueOptions());
  const std::vector<LightDetection> first = detector.Detect(scene.bgr);
  HaloColourLearner learner(BlueOptions().checks.min_halo_excess);
  learner.Observe(first, TrueIds(scene, first));
  EXPECT_TRUE(learner.learned());
  EXPECT_GT(learner.threshold(), BlueOptions().checks.min_halo_excess);
  return detector.Detect(scene.bgr, nullptr, learner.threshold());
}

TEST(BlobLightDetector, FindsLedsAmongWhiteStructures) {
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const Scene scene = MakeScene(seed, false);
    // Permissive at first: every LED, perhaps some clutter that their glow colours.
    const auto first = BlobLightDetector(BlueOptions()).Detect(scene.bgr);
    const auto ids = TrueIds(scene, first);
    EXPECT_EQ(std::count_if(ids.begin(), ids.end(), [](int id) { return id >= 0; }),
              static_cast<long>(scene.leds.size()));
    ExpectAllLedsAndNothingElse(scene, DetectWithLearnedColour(scene), 0.5);
  }
}

TEST(BlobLightDetector, SurvivesJpegCompression) {
  const Scene scene = MakeScene(3, true);
  ExpectAllLedsAndNothingElse(scene, DetectWithLearnedColour(scene), 0.6);
}

TEST(HaloColourLearner, FollowsTheLeastColouredIdentifiedLights) {
  HaloColourLearnerOptions options;
  options.min_samples = 4;
  HaloColourLearner learner(40.0, options);
  std::vector<LightDetection> d(5);
  for (int i = 0; i < 5; ++i) d[i].colour_excess = 100.0 + 10.0 * i;  // 100 ... 140
  learner.Observe(d, {0, 1, -1, -1, -1});  // two identified: not enough yet
  EXPECT_FALSE(learner.learned());
  EXPECT_EQ(learner.threshold(), 40.0);
  learner.Observe(d, {-1, -1, 2, 3, 4});  // samples 100, 110, 120, 130, 140
  EXPECT_TRUE(learner.learned());
  EXPECT_DOUBLE_EQ(learner.threshold(), 0.8 * 100.0);  // the 10 % quantile of five is the least
  EXPECT_DOUBLE_EQ(*learner.median_excess(), 120.0);
  // Dim lights (far, turbid): never below the initial, permissive threshold.
  std::vector<LightDetection> dim(64);
  for (auto& x : dim) x.colour_excess = 20.0;
  learner.Observe(dim, std::vector<int>(64, 0));
  EXPECT_EQ(learner.threshold(), 40.0);
}

TEST(BlobLightDetector, TheColourCheckIsWhatRejectsWhiteClutter) {
  // Told the lights are white, the white funnel patches and specks pass as lights as well.
  const Scene scene = MakeScene(1, false);
  BlobLightDetectorOptions white = BlueOptions();
  white.checks.colour = LightColour::kWhite;
  const auto as_white = BlobLightDetector(white).Detect(scene.bgr);
  const auto as_blue = DetectWithLearnedColour(scene);
  EXPECT_EQ(as_blue.size(), scene.leds.size());
  EXPECT_GT(as_white.size(), as_blue.size());
}

// Marine snow in water of the lights' own colour, in an image mostly of a pale deck: the halo
// of a speck is as blue as the water round it, far above the image's median. Only against its
// surroundings is it no light; a LED in the same water still is.
TEST(BlobLightDetector, SpecksInWaterOfTheLightsColourAreNotLights) {
  cv::Mat image(480, 640, CV_32FC3);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      image.at<cv::Vec3f>(y, x) =
          x < 400 ? cv::Vec3f(170.0f, 200.0f, 210.0f) : cv::Vec3f(150.0f, 90.0f, 40.0f);
    }
  }
  const std::vector<Eigen::Vector2d> specks{{470.0, 100.0}, {560.0, 200.0}, {500.0, 400.0}};
  for (const Eigen::Vector2d& s : specks) {
    cv::circle(image, cv::Point(int(s.x()), int(s.y())), 2, cv::Scalar(235, 235, 235), cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  const Led led{Eigen::Vector2d(530.3, 300.6), 3.0, 7.0};
  AddLed(led, &image);
  cv::Mat noise(image.size(), CV_32FC3);
  cv::randn(noise, 0.0, 2.0);
  image += noise;
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);

  const auto count_specks = [&](const std::vector<LightDetection>& found) {
    int n = 0;
    for (const LightDetection& d : found) {
      for (const Eigen::Vector2d& s : specks) n += (d.uv - s).norm() < 3.0;
    }
    return n;
  };
  const auto found = BlobLightDetector(BlueOptions()).Detect(bgr);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT((found[0].uv - led.uv).norm(), 0.5);

  BlobLightDetectorOptions image_median_only = BlueOptions();
  image_median_only.checks.surroundings_halo_radii = 0.0;
  EXPECT_EQ(count_specks(BlobLightDetector(image_median_only).Detect(bgr)), 3);
}

TEST(BlobLightDetector, EachDetectionCarriesACovariance) {
  const Scene scene = MakeScene(2, false);
  for (const LightDetection& d : BlobLightDetector(BlueOptions()).Detect(scene.bgr)) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(d.covariance);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
    EXPECT_LT(std::sqrt(eig.eigenvalues().maxCoeff()), 2.0);  // px: a compact core
    EXPECT_GT(d.score, 0.0);
    EXPECT_LE(d.score, 1.0);
  }
}

TEST(BlobLightDetector, LightCutByTheBorderIsFlaggedAndWidened) {
  cv::Mat image(200, 200, CV_32FC3, cv::Scalar(30, 90, 90));
  AddLed({Eigen::Vector2d(100, 100), 3.0, 7.0}, &image);
  AddLed({Eigen::Vector2d(192, 60), 3.0, 7.0}, &image);  // halo cut, core inside
  AddLed({Eigen::Vector2d(198, 140), 3.0, 7.0}, &image);  // core cut: not used
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);
  const auto found = BlobLightDetector(BlueOptions()).Detect(bgr);
  ASSERT_EQ(found.size(), 2u);
  const LightDetection& inner = found[0].uv.x() < 150 ? found[0] : found[1];
  const LightDetection& cut = found[0].uv.x() < 150 ? found[1] : found[0];
  EXPECT_FALSE(inner.at_border);
  EXPECT_TRUE(cut.at_border);
  EXPECT_GT(cut.covariance.trace(), 4.0 * inner.covariance.trace());
}

TEST(BlobLightDetector, GreyImageSkipsTheColourCheck) {
  const Scene scene = MakeScene(4, false);
  cv::Mat grey;
  cv::cvtColor(scene.bgr, grey, cv::COLOR_BGR2GRAY);
  const auto found = BlobLightDetector(BlueOptions()).Detect(grey);
  int leds = 0;
  for (const Led& led : scene.leds) {
    for (const LightDetection& d : found) leds += (d.uv - led.uv).norm() < 1.0;
  }
  EXPECT_EQ(leds, static_cast<int>(scene.leds.size()));
}

TEST(BlobLightDetector, RejectedCandidatesSayWhy) {
  const Scene scene = MakeScene(1, false);
  std::vector<RejectedLightCandidate> rejected;
  BlobLightDetector(BlueOptions()).Detect(scene.bgr, &rejected);
  ASSERT_FALSE(rejected.empty());
  int wrong_colour = 0;
  for (const auto& r : rejected) {
    EXPECT_FALSE(r.reason.empty());
    wrong_colour += r.reason.rfind("wrong colour", 0) == 0;
  }
  EXPECT_GT(wrong_colour, 0);
}

TEST(BlobLightDetector, InterlacedCombingIsUndone) {
  // A moving LED in interlaced video: the odd field sees it 4 px to the right. On the even
  // field, line-doubled, the centre is the even field's; on the raw frame it lies in between.
  cv::Mat even(240, 320, CV_32FC3, cv::Scalar(30, 90, 90)), odd = even.clone();
  AddLed({Eigen::Vector2d(150.0, 120.0), 3.0, 7.0}, &even);
  AddLed({Eigen::Vector2d(154.0, 120.0), 3.0, 7.0}, &odd);
  cv::Mat frame = even.clone();
  for (int y = 1; y < frame.rows; y += 2) odd.row(y).copyTo(frame.row(y));
  cv::Mat bgr;
  frame.convertTo(bgr, CV_8UC3);
  BlobLightDetectorOptions o = BlueOptions();
  o.deinterlace = true;
  const auto fielded = BlobLightDetector(o).Detect(bgr);
  ASSERT_EQ(fielded.size(), 1u);
  EXPECT_NEAR(fielded[0].uv.x(), 150.0, 0.3);
  EXPECT_NEAR(fielded[0].uv.y(), 120.0, 0.5);
}

TEST(LineDoubleEvenField, KeepsEvenRowsAndInterpolatesOdd) {
  cv::Mat image(5, 3, CV_8UC1);
  for (int y = 0; y < 5; ++y) image.row(y).setTo(10 * y * y);
  const cv::Mat out = LineDoubleEvenField(image);
  EXPECT_EQ(out.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(out.at<uint8_t>(1, 1), 20);  // (0 + 40) / 2
  EXPECT_EQ(out.at<uint8_t>(2, 2), 40);
  EXPECT_EQ(out.at<uint8_t>(3, 0), 100);  // (40 + 160) / 2
  EXPECT_EQ(out.at<uint8_t>(4, 0), 160);
}

TEST(BlobCandidates, ScaleOfAGaussianBlobIsItsSize) {
  for (const double s : {2.0, 4.0, 8.0}) {
    cv::Mat image(160, 160, CV_32F, cv::Scalar(20));
    for (int y = 0; y < 160; ++y) {
      for (int x = 0; x < 160; ++x) {
        const double d2 = (x - 80.0) * (x - 80.0) + (y - 80.0) * (y - 80.0);
        image.at<float>(y, x) += 100.0f * static_cast<float>(std::exp(-0.5 * d2 / (s * s)));
      }
    }
    BlobCandidateOptions o;
    o.num_scales = 13;
    o.max_sigma_px = 16.0;
    o.min_sigma_px = 1.0;
    const auto found = FindBlobCandidates(image, o);
    ASSERT_FALSE(found.empty());
    EXPECT_EQ(found[0].x, 80);
    EXPECT_EQ(found[0].y, 80);
    EXPECT_NEAR(found[0].sigma_px / s, 1.0, 0.2) << s;
    EXPECT_NEAR(found[0].response, 50.0, 10.0) << s;  // half the amplitude, at every size
  }
}

// A grey scene with one unsaturated blue-green light (a Gaussian) and beside it a lit surface:
// a flat-topped disc of the same tint (a white funnel in coloured water), or a long bar.
cv::Mat LightBesideASurface(bool bar) {
  cv::Mat image(200, 300, CV_32FC3, cv::Scalar(40, 45, 20));
  const cv::Scalar tint(150, 160, 40);
  if (bar) {
    cv::rectangle(image, cv::Rect(170, 95, 60, 10), tint, cv::FILLED);
  } else {
    cv::circle(image, cv::Point(200, 100), 12, tint, cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.0);
  for (int v = 0; v < image.rows; ++v) {
    for (int u = 0; u < image.cols; ++u) {
      const double d2 = (u - 70.3) * (u - 70.3) + (v - 100.6) * (v - 100.6);
      const float w = static_cast<float>(150.0 * std::exp(-d2 / (2.0 * 3.5 * 3.5)));
      image.at<cv::Vec3f>(v, u) += cv::Vec3f(0.9f * w, w, 0.2f * w);
    }
  }
  cv::Mat out;
  image.convertTo(out, CV_8UC3);
  return out;
}

TEST(BlobLightDetector, LitSurfacesOfTheLightsTintAreNotLights) {
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlueGreen;
  const BlobLightDetector detector(options);
  for (const bool bar : {false, true}) {
    std::vector<RejectedLightCandidate> rejected;
    const auto found = detector.Detect(LightBesideASurface(bar), &rejected);
    ASSERT_EQ(found.size(), 1u) << (bar ? "bar" : "disc");
    EXPECT_LT((found[0].uv - Eigen::Vector2d(70.3, 100.6)).norm(), 0.2);
    bool said_why = false;
    for (const auto& r : rejected) {
      said_why = said_why || r.reason == "flat top (a lit surface)" || r.reason == "elongated" ||
                 r.reason == "not a peak" || r.reason == "extended";
    }
    std::string reasons;
    for (const auto& r : rejected) reasons += r.reason + "; ";

    EXPECT_TRUE(said_why) << reasons;
  }
}

// A funnel that the water's cast saturates in two channels (cyan: B and G clipped, R not), with
// a slightly brighter rim, noise and JPEG, and a saturated LED just beside it. Small blobs on the
// funnel's edge have the funnel in half their ring: the open-sector test rejects them, and keeps
// the LED, which has the funnel in a few sectors of its ring. (Coarse-scale candidates on the rim,
// whose ring reaches past the convex edge, still pass: the renders' remaining funnel clutter.)
TEST(BlobLightDetector, SmallBlobsOnTheEdgeOfASaturatedSurfaceAreNotLights) {
  cv::Mat image(240, 320, CV_32FC3, cv::Scalar(60, 70, 30));
  cv::ellipse(image, cv::Point(120, 120), cv::Size(70, 80), 0, 0, 360, cv::Scalar(300, 300, 110),
              3);  // the rim
  cv::ellipse(image, cv::Point(120, 120), cv::Size(69, 79), 0, 0, 360, cv::Scalar(280, 280, 85),
              cv::FILLED);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.8);
  const test::Led led{Eigen::Vector2d(212.3, 121.4), 2.5, 6.0};
  test::AddLed(led, &image);
  cv::Mat noise(image.size(), CV_32FC3);
  cv::RNG(4).fill(noise, cv::RNG::NORMAL, 0.0, 6.0);
  image += noise;
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);
  std::vector<uchar> buffer;
  cv::imencode(".jpg", bgr, buffer, {cv::IMWRITE_JPEG_QUALITY, 60});
  bgr = cv::imdecode(buffer, cv::IMREAD_COLOR);
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlueGreen;
  auto small_on_the_edge = [&](const std::vector<LightDetection>& found) {
    int n = 0;
    for (const LightDetection& d : found) n += d.radius_px < 8.0 && (d.uv - led.uv).norm() > 3.0;
    return n;
  };
  auto has_led = [&](const std::vector<LightDetection>& found) {
    return std::any_of(found.begin(), found.end(),
                       [&](const LightDetection& d) { return (d.uv - led.uv).norm() < 0.5; });
  };
  const auto with_test = BlobLightDetector(options).Detect(bgr);
  EXPECT_TRUE(has_led(with_test));
  EXPECT_EQ(small_on_the_edge(with_test), 0);
  options.checks.min_open_drop_fraction = 0.0;
  // Without it the whole funnel (round, r ~77 px) passes the checks as a light; its glow would
  // hide the blobs on its edge: keep them visible.
  options.max_response_in_halo = 0.0;
  const auto without_test = BlobLightDetector(options).Detect(bgr);
  EXPECT_TRUE(has_led(without_test));
  EXPECT_GT(small_on_the_edge(without_test), 0);
}

TEST(BlobCandidates, ALargeStructureDoesNotHideASmallLightBesideIt) {
  cv::Mat image(200, 200, CV_32F, cv::Scalar(20));
  cv::circle(image, cv::Point(100, 100), 40, cv::Scalar(200), cv::FILLED);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.5);
  for (int y = 0; y < 200; ++y) {
    for (int x = 0; x < 200; ++x) {
      const double d2 = (x - 100.0) * (x - 100.0) + (y - 152.0) * (y - 152.0);
      image.at<float>(y, x) += 120.0f * static_cast<float>(std::exp(-0.5 * d2 / 4.0));
    }
  }
  BlobCandidateOptions o;
  o.max_sigma_px = 40.0;
  o.num_scales = 10;
  const auto found = FindBlobCandidates(image, o);
  bool light = false;
  for (const BlobCandidate& c : found) {
    light = light || (std::abs(c.x - 100) <= 1 && std::abs(c.y - 152) <= 1 && c.sigma_px < 4.0);
    EXPECT_LT(c.sigma_px, 39.0);  // never a maximum at the largest scale
  }
  EXPECT_TRUE(light);
  o.keep_largest_scale = true;
  o.max_sigma_px = 20.0;  // the disc's scale (~28 px) is beyond the range: its maximum is at 20
  bool at_largest = false;
  for (const BlobCandidate& c : FindBlobCandidates(image, o)) at_largest |= c.sigma_px > 19.9;
  EXPECT_TRUE(at_largest);
}

// A light a few decimetres from the lens: a saturated disc of 50 px radius in a blue glow of
// 50 px sigma (a blob scale of ~45 px, beyond the 28 px that the scales reached before). Beside
// it a lit patch about as large and as bright, in the same glow, but twice as long as it is wide
// (a white funnel's interior between its vanes): the light is found, the patch is not, and says
// why. (Either half fails with the old scales or without the roundness limit of large cores.)
TEST(BlobLightDetector, AVeryCloseLightIsFoundAndALargeLitPatchIsNot) {
  cv::Mat image(512, 640, CV_32FC3, cv::Scalar(60, 70, 30));
  const Led close_light{Eigen::Vector2d(190.3, 255.6), 50.0, 50.0};
  AddLed(close_light, &image);
  cv::Mat patch(image.size(), CV_32FC3, cv::Scalar(0, 0, 0));
  cv::ellipse(patch, cv::Point(480, 256), cv::Size(70, 32), 0, 0, 360,
              cv::Scalar(400, 400, 400), cv::FILLED);
  cv::Mat glow;
  cv::GaussianBlur(patch, glow, cv::Size(0, 0), 20.0);
  image += patch + glow.mul(cv::Scalar(0.8, 0.45, 0.1));
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlue;
  std::vector<RejectedLightCandidate> rejected;
  const auto found = BlobLightDetector(options).Detect(bgr, &rejected);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_LT((found[0].uv - close_light.uv).norm(), 1.0);
  bool patch_said_why = false;
  for (const auto& r : rejected) {
    patch_said_why |= (r.uv - Eigen::Vector2d(480, 256)).norm() < 20.0 && r.reason == "elongated";
  }
  EXPECT_TRUE(patch_said_why);
}

// A light within decimetres of the lens whitens its own glow: its shape passes and its colour
// fails, and such a candidate is marked for a tracked prediction to overrule, with its core's
// covariance. A small white blob of the same kind is not (it is a fitting or a speck).
TEST(BlobLightDetector, ACloseLightRejectedForItsColourAloneMayBeOverruled) {
  cv::Mat image(512, 640, CV_32FC3, cv::Scalar(60, 70, 30));
  const auto add_white_light = [&](const Eigen::Vector2d& uv, double core_px, double halo_px) {
    for (int y = 0; y < image.rows; ++y) {
      for (int x = 0; x < image.cols; ++x) {
        const double d2 = (x - uv.x()) * (x - uv.x()) + (y - uv.y()) * (y - uv.y());
        const float level =
            static_cast<float>((d2 <= core_px * core_px ? 400.0 : 0.0) +
                               300.0 * std::exp(-0.5 * d2 / (halo_px * halo_px)));
        image.at<cv::Vec3f>(y, x) += cv::Vec3f(level, level, level);
      }
    }
  };
  const Eigen::Vector2d close_uv(300.4, 250.7), small_uv(560.2, 90.6);
  add_white_light(close_uv, 50.0, 50.0);
  add_white_light(small_uv, 2.0, 3.0);
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlue;
  std::vector<RejectedLightCandidate> rejected;
  EXPECT_TRUE(BlobLightDetector(options).Detect(bgr, &rejected).empty());
  int close_overrulable = 0, small_overrulable = 0;
  for (const auto& r : rejected) {
    if (!r.overrulable) {
      EXPECT_TRUE(r.covariance.isZero());
      continue;
    }
    EXPECT_EQ(r.reason.rfind("wrong colour", 0), 0u) << r.reason;
    EXPECT_GT(r.sigma_px, options.close_light_min_sigma_px);
    EXPECT_GT(r.covariance.trace(), 0.0);
    close_overrulable += (r.uv - close_uv).norm() < 1.0;
    small_overrulable += (r.uv - small_uv).norm() < 5.0;
  }
  EXPECT_GE(close_overrulable, 1);
  EXPECT_EQ(small_overrulable, 0);
}

// A large round bright plateau among small lights (a white funnel's interior ringed by LEDs 1.5
// plateau radii from its centre, in a grey image where no colour tells them apart) is not a light
// a few decimetres away: that would outshine the others and lie far from them in the image. It
// is judged after them, and hides none.
TEST(BlobLightDetector, ALargePlateauAmongLightsIsNotACloseLight) {
  cv::Mat image(480, 640, CV_32FC3, cv::Scalar(60, 70, 30));
  cv::circle(image, cv::Point(320, 240), 60, cv::Scalar(400, 400, 400), cv::FILLED);
  cv::GaussianBlur(image, image, cv::Size(0, 0), 1.5);
  std::vector<Led> leds;
  for (int k = 0; k < 6; ++k) {
    const double a = 2.0 * 3.14159265358979 * k / 6.0;
    leds.push_back({Eigen::Vector2d(320.3 + 90.0 * std::cos(a), 240.6 + 90.0 * std::sin(a)), 3.0,
                    6.0});
    AddLed(leds.back(), &image);
  }
  cv::Mat bgr, grey;
  image.convertTo(bgr, CV_8UC3);
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  std::vector<RejectedLightCandidate> rejected;
  const auto found = BlobLightDetector(BlueOptions()).Detect(grey, &rejected);
  EXPECT_EQ(found.size(), leds.size());
  for (const Led& led : leds) {
    EXPECT_TRUE(std::any_of(found.begin(), found.end(), [&](const LightDetection& d) {
      return (d.uv - led.uv).norm() < 1.0;
    })) << "LED at " << led.uv.transpose();
  }
  bool said_why = false;
  for (const auto& r : rejected) {
    said_why |= (r.uv - Eigen::Vector2d(320, 240)).norm() < 5.0 &&
                r.reason == "larger than a light among lights";
  }
  EXPECT_TRUE(said_why);
}

TEST(BlobLightDetector, BadInputThrows) {
  EXPECT_THROW(BlobLightDetector().Detect(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(BlobLightDetector().Detect(cv::Mat(10, 10, CV_32FC3)), std::invalid_argument);
  BlobLightDetectorOptions o;
  o.core.core_level = 1.5;
  EXPECT_THROW(BlobLightDetector{o}, std::invalid_argument);
  o = {};
  o.candidates.num_scales = 0;
  EXPECT_THROW(BlobLightDetector{o}, std::invalid_argument);
}

}  // namespace
}  // namespace auvdock
