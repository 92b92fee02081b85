// The second look for missed lights (guided_light_search.h) and the per-image pipeline that uses
// it (mono_light_pipeline.h), on images drawn here: Gaussian blue-green blobs on a textured
// background, independent of the simulator's renderer.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/calibration.h"
#include "auvdock/sim/image_blobs.h"
#include "auvdock/vision/guided_light_search.h"
#include "auvdock/vision/mono_light_pipeline.h"
#include "auvdock/vision/paper_baseline_pipeline.h"
#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

constexpr double kDeg = M_PI / 180.0;

cv::Mat Background(const PinholeRadtanCamera& camera, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat image(camera.height(), camera.width(), CV_32FC3);
  cv::Mat texture(camera.height() / 16, camera.width() / 16, CV_32F);
  rng.fill(texture, cv::RNG::NORMAL, 0.0, 6.0);
  cv::resize(texture, texture, image.size(), 0, 0, cv::INTER_CUBIC);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const float t = texture.at<float>(y, x);
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(60.0f + t, 70.0f + t, 30.0f + t);
    }
  }
  return image;
}

// Blue-green lights of peak amplitude `amplitude` (gray levels over the background) and blob
// size sigma_px at the projections of the given lights; returns the 8-bit image.
cv::Mat DrawLights(cv::Mat image, const DockModel& dock, const PinholeRadtanCamera& camera,
                   const Pose3& T_C_D, const std::vector<std::pair<int, double>>& id_amplitude,
                   double sigma_px, uint64_t seed) {
  for (const auto& [id, amplitude] : id_amplitude) {
    const auto uv = camera.Project(T_C_D * dock.FindLight(id)->p_D);
    AddGaussianBlob(*uv, sigma_px, Eigen::Vector3d(amplitude, amplitude, 0.2 * amplitude), &image);
  }
  cv::Mat noise(image.size(), CV_32FC3);
  cv::RNG(seed + 1).fill(noise, cv::RNG::NORMAL, 0.0, 1.5);
  image += noise;
  cv::Mat out;
  image.convertTo(out, CV_8UC3);
  return out;
}

BlobLightDetectorOptions BlueGreen() {
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlueGreen;
  return options;
}

Pose3 ViewFromAbove(double distance_m) {
  Eigen::Matrix3d R_D_C;  // looking straight down
  R_D_C << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  R_D_C = ExpSO3(Eigen::Vector3d(0.05, -0.03, 0.4)) * R_D_C;
  const Pose3 T_D_C(Eigen::Quaterniond(R_D_C), Eigen::Vector3d(0.1, -0.05, 0.0) -
                                                    distance_m * R_D_C.col(2));
  return T_D_C.Inverse();
}

TEST(PredictLights, CovarianceIsThePosesPropagatedThroughTheProjection) {
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 T_C_D = ViewFromAbove(4.0);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
  const Eigen::Matrix<double, 6, 6> P = 1e-4 * (A * A.transpose()) +
                                        1e-6 * Eigen::Matrix<double, 6, 6>::Identity();
  const std::vector<int> skip = {dock.lights[0].id};
  const std::vector<PredictedLight> predictions = PredictLights(dock, camera, T_C_D, P, skip);
  ASSERT_EQ(predictions.size(), dock.lights.size() - 1);
  for (const PredictedLight& p : predictions) {
    EXPECT_NE(p.light_id, dock.lights[0].id);
    const Eigen::Vector3d p_D = dock.FindLight(p.light_id)->p_D;
    // Numerical Jacobian of the pixel over (dtheta, dt): R <- Exp(dtheta) R, t <- t + dt.
    Eigen::Matrix<double, 2, 6> J;
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
      d[k] = 1e-6;
      auto project = [&](const Eigen::Matrix<double, 6, 1>& delta) {
        const Eigen::Vector3d p_C = ExpSO3(delta.head<3>()) * (T_C_D.R() * p_D) + T_C_D.p +
                                    delta.tail<3>();
        return *camera.Project(p_C);
      };
      J.col(k) = (project(d) - project(-d)) / 2e-6;
    }
    const Eigen::Matrix2d expected = J * P * J.transpose();
    EXPECT_LT((p.covariance - expected).norm(), 1e-3 * expected.norm());
    EXPECT_LT((p.uv - *camera.Project(T_C_D * p_D)).norm(), 1e-9);
    EXPECT_NEAR(p.radius_px,
                camera.fx() * dock.FindLight(p.light_id)->radius_m / (T_C_D * p_D).z(), 1e-9);
  }
}

TEST(PredictLights, LightsBehindTheCameraOrOutsideTheImageAreNotPredicted) {
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 away = Pose3(ExpQuaternion(Eigen::Vector3d(M_PI, 0.0, 0.0)), Eigen::Vector3d(0, 0, 0)) *
                     ViewFromAbove(4.0);
  EXPECT_TRUE(PredictLights(dock, camera, away, Eigen::Matrix<double, 6, 6>::Zero(), {}).empty());
  Pose3 aside = ViewFromAbove(4.0);
  aside.p.x() += 50.0;  // far to the side: outside the image
  EXPECT_TRUE(PredictLights(dock, camera, aside, Eigen::Matrix<double, 6, 6>::Zero(), {}).empty());
}

TEST(GuidedLightSearch, FindsADimLightWhereItIsPredictedAndNothingElsewhere) {
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 T_C_D = ViewFromAbove(5.0);
  std::vector<std::pair<int, double>> lights;
  for (size_t i = 0; i < dock.lights.size(); ++i) {
    lights.emplace_back(dock.lights[i].id, i == 2 ? 40.0 : 180.0);  // light 2 is dim
  }
  const cv::Mat image = DrawLights(Background(camera, 3), dock, camera, T_C_D, lights, 2.5, 3);
  const BlobLightDetector detector(BlueGreen());
  const std::vector<LightDetection> first = detector.Detect(image);
  const Eigen::Vector2d dim_uv = *camera.Project(T_C_D * dock.lights[2].p_D);
  for (const LightDetection& d : first) {
    ASSERT_GT((d.uv - dim_uv).norm(), 5.0) << "the full-image pass should miss the dim light";
  }
  ASSERT_EQ(first.size(), dock.lights.size() - 1);

  const GuidedLightSearch search(BlueGreen());
  PredictedLight prediction;
  prediction.light_id = dock.lights[2].id;
  prediction.uv = dim_uv + Eigen::Vector2d(1.0, -0.8);  // the pose's error
  prediction.covariance = 0.5 * Eigen::Matrix2d::Identity();
  prediction.radius_px = 1.0;
  std::vector<GuidedDetection> found = search.Search(image, {prediction}, first, 40.0);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].light_id, dock.lights[2].id);
  // A dim light on a textured background: good to about its own stated accuracy.
  const double stated = std::sqrt(found[0].detection.covariance.trace());
  EXPECT_GT(stated, 0.0);
  EXPECT_LT((found[0].detection.uv - dim_uv).norm(), std::max(0.5, 3.0 * stated));

  // Nothing where no light is; a prediction whose gate holds a detection is not searched; a
  // prediction too uncertain to guide is not searched.
  PredictedLight empty = prediction;
  empty.uv = Eigen::Vector2d(40.0, 40.0);
  EXPECT_TRUE(search.Search(image, {empty}, first, 40.0).empty());
  PredictedLight judged = prediction;
  judged.uv = first[0].uv + Eigen::Vector2d(1.0, 0.0);
  EXPECT_TRUE(search.Search(image, {judged}, first, 40.0).empty());
  PredictedLight vague = prediction;
  vague.covariance = 100.0 * Eigen::Matrix2d::Identity();
  EXPECT_TRUE(search.Search(image, {vague}, first, 40.0).empty());
}

TEST(GuidedLightSearch, BadOptionsThrow) {
  GuidedLightSearchOptions options;
  options.max_gate_px = 0.5;  // below the floor
  EXPECT_THROW(GuidedLightSearch(BlueGreen(), options), std::invalid_argument);
  options = {};
  options.halo_excess_fraction = 2.0;
  EXPECT_THROW(GuidedLightSearch(BlueGreen(), options), std::invalid_argument);
  const GuidedLightSearch search(BlueGreen());
  EXPECT_THROW(search.Search(cv::Mat(), {}, {}, 40.0), std::invalid_argument);
}

CameraCalibration MonoCalibration() {
  CameraCalibration calibration;
  calibration.name = "cam2";
  calibration.intrinsics = test::DefaultMonoCamera();
  return calibration;
}

MonoLightPipelineOptions PipelineOptions(bool second_look) {
  MonoLightPipelineOptions options;
  options.detector = BlueGreen();
  options.guided_search = second_look;
  options.weak_pass = second_look;
  return options;
}

TEST(MonoLightPipeline, DimFarLightsGetAPoseFromTheLaxerPass) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 T_C_D = ViewFromAbove(7.0);
  std::vector<std::pair<int, double>> lights;
  for (const DockLight& light : dock.lights) lights.emplace_back(light.id, 40.0);
  const cv::Mat image =
      DrawLights(Background(camera.intrinsics, 5), dock, camera.intrinsics, T_C_D, lights, 2.5, 5);

  MonoLightPipeline first_pass_only(camera, dock, PipelineOptions(false));
  const MonoLightFrame without = first_pass_only.Process(image);
  EXPECT_FALSE(without.pose.T_C_D.has_value());
  EXPECT_TRUE(without.detections.empty());

  MonoLightPipeline pipeline(camera, dock, PipelineOptions(true));
  const MonoLightFrame frame = pipeline.Process(image);
  ASSERT_TRUE(frame.pose.T_C_D.has_value()) << frame.pose.reason;
  EXPECT_TRUE(frame.from_weak_pass);
  ASSERT_EQ(frame.detections.size(), frame.pose.light_ids.size());
  int correct = 0;
  for (size_t i = 0; i < frame.detections.size(); ++i) {
    const int id = frame.pose.light_ids[i];
    ASSERT_GE(id, 0) << "only verified weak detections are kept";
    const Eigen::Vector2d truth = *camera.intrinsics.Project(T_C_D * dock.FindLight(id)->p_D);
    correct += (frame.detections[i].uv - truth).norm() < 0.5;
  }
  EXPECT_EQ(correct, static_cast<int>(dock.lights.size()));
  EXPECT_LT((frame.pose.T_C_D->p - T_C_D.p).norm(), 0.15);
}

// The laxer pass's pose must see the deck from weak_min_view_elevation_deg up: seen edge-on a
// layout's lights lie near one image line, where a cable's or a rim's row of weak bumps fits it.
// The same dim lights seen 7 deg up give a pose only when the limit is the matcher's 5 deg.
TEST(MonoLightPipeline, TheLaxerPassTakesNoPoseNearlyEdgeOnToTheDeck) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 T_C_D = test::ViewFromElevation(dock, 3.0, 7.0 * kDeg, 45.0 * kDeg);
  std::vector<std::pair<int, double>> lights;
  for (const DockLight& light : dock.lights) lights.emplace_back(light.id, 40.0);
  const cv::Mat image =
      DrawLights(Background(camera.intrinsics, 8), dock, camera.intrinsics, T_C_D, lights, 2.5, 8);

  MonoLightPipeline refusing(camera, dock, PipelineOptions(true));  // 10 deg by default
  const MonoLightFrame refused = refusing.Process(image);
  EXPECT_FALSE(refused.pose.T_C_D.has_value());
  EXPECT_FALSE(refused.pose.reason.empty());

  MonoLightPipelineOptions options = PipelineOptions(true);
  options.weak_min_view_elevation_deg = 5.0;
  MonoLightPipeline accepting(camera, dock, options);
  const MonoLightFrame frame = accepting.Process(image);
  ASSERT_TRUE(frame.pose.T_C_D.has_value()) << frame.pose.reason;
  EXPECT_TRUE(frame.from_weak_pass);
  EXPECT_LT((frame.pose.T_C_D->Inverse().p - T_C_D.Inverse().p).norm(), 0.15);
}

TEST(MonoLightPipeline, WeakClutterAloneGivesNoPose) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  cv::Mat image = Background(camera.intrinsics, 7);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(20.0, 620.0), v(20.0, 490.0);
  for (int k = 0; k < 25; ++k) {  // dim blue-green specks at random places
    AddGaussianBlob(Eigen::Vector2d(u(rng), v(rng)), 2.0, Eigen::Vector3d(40, 40, 8), &image);
  }
  cv::Mat bgr;
  image.convertTo(bgr, CV_8UC3);
  MonoLightPipeline pipeline(camera, dock, PipelineOptions(true));
  const MonoLightFrame frame = pipeline.Process(bgr);
  EXPECT_FALSE(frame.pose.T_C_D.has_value());
  EXPECT_FALSE(frame.pose.reason.empty());
}

TEST(MonoLightPipeline, ATrackedPoseFindsTheLightThatFaded) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 first_view = ViewFromAbove(4.0);
  Pose3 second_view = first_view;
  second_view.p += Eigen::Vector3d(0.03, -0.02, 0.0);  // the vehicle moved a little
  std::vector<std::pair<int, double>> bright, one_dim;
  for (size_t i = 0; i < dock.lights.size(); ++i) {
    bright.emplace_back(dock.lights[i].id, 180.0);
    one_dim.emplace_back(dock.lights[i].id, i == 1 ? 35.0 : 180.0);
  }
  MonoLightPipeline pipeline(camera, dock, PipelineOptions(true));
  const MonoLightFrame frame1 = pipeline.Process(
      DrawLights(Background(camera.intrinsics, 9), dock, camera.intrinsics, first_view, bright, 3.0, 9));
  ASSERT_TRUE(frame1.pose.T_C_D.has_value()) << frame1.pose.reason;
  const MonoLightFrame frame2 = pipeline.Process(DrawLights(
      Background(camera.intrinsics, 10), dock, camera.intrinsics, second_view, one_dim, 3.0, 10));
  ASSERT_TRUE(frame2.pose.T_C_D.has_value()) << frame2.pose.reason;
  EXPECT_EQ(frame2.first_pass_detections, static_cast<int>(dock.lights.size()) - 1);
  EXPECT_EQ(frame2.guided_detections, 1);
  const Eigen::Vector2d dim_uv = *camera.intrinsics.Project(second_view * dock.lights[1].p_D);
  bool found = false;
  for (size_t i = 0; i < frame2.detections.size(); ++i) {
    if (frame2.pose.light_ids[i] != dock.lights[1].id) continue;
    found = true;
    const double stated = std::sqrt(frame2.detections[i].covariance.trace());
    EXPECT_LT((frame2.detections[i].uv - dim_uv).norm(), std::max(0.5, 3.0 * stated)) << stated;
  }
  EXPECT_TRUE(found);
}

// Two bright lights and two bright clutter blobs make min_lights first-pass detections that no
// pose explains; the dock's four dim lights are found by the laxer pass, which now also follows
// a failed identification (weak_pass_after_failed_identification), and settle it.
TEST(MonoLightPipeline, AFailedIdentificationGetsTheLaxerPassToo) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const Pose3 T_C_D = ViewFromAbove(6.0);
  std::vector<std::pair<int, double>> lights;
  for (size_t i = 0; i < dock.lights.size(); ++i) {
    lights.emplace_back(dock.lights[i].id, i == 0 || i == 3 ? 150.0 : 40.0);
  }
  cv::Mat background = Background(camera.intrinsics, 11);
  for (const Eigen::Vector2d& clutter : {Eigen::Vector2d(80, 400), Eigen::Vector2d(560, 90)}) {
    AddGaussianBlob(clutter, 2.5, Eigen::Vector3d(150, 150, 30), &background);
  }
  const cv::Mat image = DrawLights(background, dock, camera.intrinsics, T_C_D, lights, 2.5, 11);
  MonoLightPipelineOptions only_after_few = PipelineOptions(true);
  only_after_few.weak_pass_after_failed_identification = false;
  MonoLightPipeline before(camera, dock, only_after_few);
  const MonoLightFrame without = before.Process(image);
  ASSERT_EQ(without.first_pass_detections, 4);
  EXPECT_FALSE(without.pose.T_C_D.has_value());

  MonoLightPipeline pipeline(camera, dock, PipelineOptions(true));
  const MonoLightFrame frame = pipeline.Process(image);
  ASSERT_TRUE(frame.pose.T_C_D.has_value()) << frame.pose.reason;
  EXPECT_TRUE(frame.from_weak_pass);
  EXPECT_EQ(frame.pose.num_lights, static_cast<int>(dock.lights.size()));
  EXPECT_LT((frame.pose.T_C_D->p - T_C_D.p).norm(), 0.1);
}

// Detections of a view far from ViewFromAbove(4.0) (2 m higher, turned 1.2 rad about the axis):
// a track from that view cannot label them.
test::View ViewFarFromTheTrack(const DockModel& dock, const CameraCalibration& camera,
                               std::mt19937_64* rng) {
  Pose3 elsewhere = ViewFromAbove(6.0);
  elsewhere.q = ExpQuaternion(Eigen::Vector3d(0.0, 0.0, 1.2)) * elsewhere.q;
  return test::MakeView(dock, camera.intrinsics, elsewhere, test::AllLightIds(dock), 0, 0.2, *rng);
}

// A retry's pose that the caller refuses (the weak pass's: too little of the dock explained) is
// no pose and is not tracked from: the tracking state stays that of the last accepted pose.
TEST(MonoLightPoser, ARefusedRetryLeavesTheTrackAsItWas) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  std::mt19937_64 rng(4);
  const test::View view = test::MakeView(dock, camera.intrinsics, ViewFromAbove(4.0),
                                         test::AllLightIds(dock), 0, 0.2, rng);
  MonoLightPoser poser(camera, dock);
  ASSERT_TRUE(poser.Process(view.detections).T_C_D.has_value());
  const Pose3 tracked = *poser.TrackedPose();
  const test::View other = ViewFarFromTheTrack(dock, camera, &rng);
  int asked = 0;
  const MonoPoseResult refused = poser.Retry(other.detections, [&](const MonoPoseResult& r) {
    ++asked;
    EXPECT_TRUE(r.T_C_D.has_value());
    return false;
  });
  EXPECT_EQ(asked, 1);
  EXPECT_FALSE(refused.T_C_D.has_value());
  EXPECT_FALSE(refused.reason.empty());
  EXPECT_EQ(refused.light_ids, std::vector<int>(other.detections.size(), -1));
  ASSERT_TRUE(poser.TrackedPose().has_value());
  EXPECT_LT((poser.TrackedPose()->p - tracked.p).norm(), 1e-12);
  const MonoPoseResult accepted =
      poser.Retry(other.detections, [](const MonoPoseResult&) { return true; });
  ASSERT_TRUE(accepted.T_C_D.has_value());
  EXPECT_LT((poser.TrackedPose()->p - accepted.T_C_D->p).norm(), 1e-12);
}

// Tracking carries a labelling down to a view edge-on to the deck, where the lights fit as well as
// anywhere; no camera over a dock on the seabed sees it from there (CameraAboveTheDeck, the
// matcher's own test of its hypotheses), so that frame has no pose and the track stays where it
// was.
TEST(MonoLightPoser, ATrackedPoseEdgeOnToTheDeckIsRefused) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  auto descend = [&](const MonoLightPoserOptions& options) {
    std::mt19937_64 rng(6);
    MonoLightPoser poser(camera, dock, options);
    std::vector<MonoPoseResult> results;
    for (double elevation : {30.0, 24.0, 18.0, 13.0, 9.0, 6.0, 4.0}) {
      const test::View view =
          test::MakeView(dock, camera.intrinsics,
                         test::ViewFromElevation(dock, 2.5, elevation * kDeg, 45.0 * kDeg),
                         test::AllLightIds(dock), 0, 0.05, rng);
      results.push_back(poser.Process(view.detections));
    }
    return results;
  };
  const std::vector<MonoPoseResult> refused = descend(MonoLightPoserOptions{});
  for (size_t k = 0; k + 1 < refused.size(); ++k) {
    ASSERT_TRUE(refused[k].T_C_D.has_value()) << k << ": " << refused[k].reason;
    EXPECT_EQ(refused[k].tracked, k > 0);
  }
  EXPECT_FALSE(refused.back().T_C_D.has_value());
  EXPECT_EQ(refused.back().reason, "tracking: the camera would be edge-on to the deck or under it");
  MonoLightPoserOptions no_limit;
  no_limit.ransac.min_view_elevation_deg = 0.0;
  const std::vector<MonoPoseResult> kept = descend(no_limit);
  ASSERT_TRUE(kept.back().T_C_D.has_value()) << kept.back().reason;
  EXPECT_TRUE(kept.back().tracked);
  const Pose3 truth = test::ViewFromElevation(dock, 2.5, 4.0 * kDeg, 45.0 * kDeg);
  EXPECT_LT((kept.back().T_C_D->Inverse().p - truth.Inverse().p).norm(), 0.05);
}

// Guesses only tracking may label: a failed tracked-only frame identifies nothing from scratch
// and leaves the tracking state as it was.
TEST(MonoLightPoser, TrackedOnlyNeverIdentifiesFromScratchNorForgetsTheTrack) {
  const CameraCalibration camera = MonoCalibration();
  const DockModel dock = test::LoadDock("t_shape.yaml");
  std::mt19937_64 rng(3);
  const Pose3 first = ViewFromAbove(4.0);
  const test::View view =
      test::MakeView(dock, camera.intrinsics, first, test::AllLightIds(dock), 0, 0.2, rng);
  MonoLightPoser fresh(camera, dock);
  const MonoPoseResult untracked = fresh.ProcessTrackedOnly(view.detections);
  EXPECT_FALSE(untracked.T_C_D.has_value());
  EXPECT_EQ(untracked.reason, "nothing to track");
  ASSERT_TRUE(fresh.Retry(view.detections).T_C_D.has_value());

  MonoLightPoser poser(camera, dock);
  ASSERT_TRUE(poser.Process(view.detections).T_C_D.has_value());
  const Pose3 tracked = *poser.TrackedPose();
  // Tracking cannot label the far view, and nothing else may.
  const test::View other = ViewFarFromTheTrack(dock, camera, &rng);
  const MonoPoseResult result = poser.ProcessTrackedOnly(other.detections);
  EXPECT_FALSE(result.T_C_D.has_value());
  EXPECT_EQ(result.reason.rfind("tracking: ", 0), 0u) << result.reason;
  ASSERT_TRUE(poser.TrackedPose().has_value());
  EXPECT_LT((poser.TrackedPose()->p - tracked.p).norm(), 1e-12);
  EXPECT_TRUE(poser.Retry(other.detections).T_C_D.has_value());  // from scratch, on request
}

// The per-frame pipeline of `run` (blob detector): after the frame's pose, each camera gets a
// second look where the pose puts the lights it missed (step 6).
TEST(PaperBaselinePipeline, TheSecondLookAddsADimLightWithItsIdentity) {
  Calibration calibration;
  calibration.cameras.push_back(MonoCalibration());
  calibration.cameras.back().role = CameraRole::kMono;
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const PinholeRadtanCamera& camera = calibration.cameras.back().intrinsics;
  const Pose3 T_C_D = ViewFromAbove(4.0);
  std::vector<std::pair<int, double>> lights;
  for (size_t i = 0; i < dock.lights.size(); ++i) {
    lights.emplace_back(dock.lights[i].id, i == 3 ? 35.0 : 180.0);
  }
  const cv::Mat image = DrawLights(Background(camera, 11), dock, camera, T_C_D, lights, 3.0, 11);
  const Pose3 T_D_B = T_C_D.Inverse();  // T_B_C is the identity
  for (const bool second_look : {false, true}) {
    PaperBaselineOptions options;
    options.detector_kind = LightDetectorKind::kBlob;
    options.guided_search = second_look;
    PaperBaselinePipeline pipeline(calibration, dock, options);
    const BaselineFrame frame = pipeline.Process(0, cv::Mat(), cv::Mat(), image, T_D_B);
    ASSERT_TRUE(frame.T_D_B.has_value()) << frame.reason;
    int dim_found = 0;
    const Eigen::Vector2d dim_uv = *camera.Project(T_C_D * dock.lights[3].p_D);
    for (size_t i = 0; i < frame.mono.detections.size(); ++i) {
      if (frame.mono.light_ids[i] != dock.lights[3].id) continue;
      ++dim_found;
      EXPECT_LT((frame.mono.detections[i].uv - dim_uv).norm(), 0.5);
    }
    EXPECT_EQ(dim_found, second_look ? 1 : 0);
    EXPECT_EQ(frame.mono.guided, second_look ? 1 : 0);
  }
}

}  // namespace
}  // namespace auvdock
