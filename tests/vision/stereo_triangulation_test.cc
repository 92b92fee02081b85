#include "auvdock/vision/stereo_triangulation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "auvdock/geometry/so3.h"
#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

struct Rig {
  CameraCalibration left, right;
  Pose3 T_R_L;  // S (= left camera) -> right camera
};

Rig DefaultRig() {
  const Calibration calibration = MakeCalibration(test::DefaultScenario());
  Rig rig;
  rig.left = *calibration.FindCameraByRole(CameraRole::kStereoLeft);
  rig.right = *calibration.FindCameraByRole(CameraRole::kStereoRight);
  rig.T_R_L = rig.right.T_B_C.Inverse() * rig.left.T_B_C;
  return rig;
}

// "Pixel" of a point with any depth sign (x/z, y/z through the distortion), to build
// inputs for points behind a camera.
Eigen::Vector2d PixelOf(const PinholeRadtanCamera& camera, const Eigen::Vector3d& p) {
  return camera.ProjectNormalized(p.head<2>() / p.z());
}

TEST(TriangulateLinear, NoiseFreePointsAreRecoveredExactly) {
  const Rig rig = DefaultRig();
  int tested = 0;
  for (double z = 0.5; z <= 25.0; z *= 1.3) {
    for (double x = -0.6; x <= 0.6; x += 0.3) {
      for (double y = -0.5; y <= 0.5; y += 0.25) {
        const Eigen::Vector3d p_S(x * z, y * z, z);
        const auto uv_l = rig.left.intrinsics.Project(p_S);
        const auto uv_r = rig.right.intrinsics.Project(rig.T_R_L * p_S);
        if (!rig.left.intrinsics.InImage(*uv_l) || !rig.right.intrinsics.InImage(*uv_r)) continue;
        const TriangulatedPoint point = TriangulateLinear(*uv_l, *uv_r, rig.left, rig.right, 0.3);
        ASSERT_TRUE(point.ok) << point.reason << " " << p_S.transpose();
        EXPECT_LT((point.p_S - p_S).norm(), 1e-10 * z * z) << p_S.transpose();
        EXPECT_LT(point.reprojection_rms_px, 1e-8);
        ++tested;
      }
    }
  }
  EXPECT_GT(tested, 100);
}

TEST(TriangulateLinear, CovarianceMatchesMonteCarloAndDepthIsTheWeakDirection) {
  const Rig rig = DefaultRig();
  const double sigma = 0.3;
  const Eigen::Vector3d p_S(0.4, -0.3, 3.0);
  const Eigen::Vector2d uv_l = *rig.left.intrinsics.Project(p_S);
  const Eigen::Vector2d uv_r = *rig.right.intrinsics.Project(rig.T_R_L * p_S);
  const TriangulatedPoint reference = TriangulateLinear(uv_l, uv_r, rig.left, rig.right, sigma);
  ASSERT_TRUE(reference.ok) << reference.reason;

  constexpr int kSamples = 2000;  // relative error of a sample variance: sqrt(2 / N) = 3 %
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<Eigen::Vector3d> samples;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Vector2d l = uv_l + Eigen::Vector2d(noise(rng), noise(rng));
    const Eigen::Vector2d r = uv_r + Eigen::Vector2d(noise(rng), noise(rng));
    const TriangulatedPoint point = TriangulateLinear(l, r, rig.left, rig.right, sigma);
    ASSERT_TRUE(point.ok) << point.reason;
    samples.push_back(point.p_S);
    mean += point.p_S / kSamples;
  }
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& s : samples) C += (s - mean) * (s - mean).transpose() / (kSamples - 1.0);
  std::printf("triangulation Monte-Carlo (%d samples) sample/reported variance x y z:", kSamples);
  for (int k = 0; k < 3; ++k) {
    const double ratio = C(k, k) / reference.covariance(k, k);
    std::printf(" %.3f", ratio);
    EXPECT_NEAR(ratio, 1.0, 0.15) << k;
  }
  double nees = 0.0;
  const Eigen::Matrix3d information = reference.covariance.inverse();
  for (const auto& s : samples) nees += (s - p_S).dot(information * (s - p_S)) / kSamples;
  std::printf("; mean NEES %.3f (expected 3)\n", nees);
  EXPECT_NEAR(nees, 3.0, 0.3);

  // The largest axis of the covariance lies along the viewing ray and is much longer.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(reference.covariance);
  const Eigen::Vector3d weak = eigen.eigenvectors().col(2);
  const double ray_angle = std::acos(std::abs(weak.dot(p_S.normalized())));
  const double elongation = std::sqrt(eigen.eigenvalues()(2) / eigen.eigenvalues()(1));
  std::printf("weak axis %.2f deg from the ray, sigma ratio %.1f, depth sigma %.4f m\n",
              ray_angle * 180.0 / M_PI, elongation, std::sqrt(eigen.eigenvalues()(2)));
  EXPECT_LT(ray_angle, 5.0 * M_PI / 180.0);
  EXPECT_GT(elongation, 5.0);
  // Textbook depth sigma z^2 / (f b) * sqrt(2) sigma (disparity noise of two pixels).
  const double f = rig.left.intrinsics.fx();
  const double baseline = rig.T_R_L.p.norm();
  EXPECT_NEAR(std::sqrt(reference.covariance(2, 2)),
              p_S.z() * p_S.z() / (f * baseline) * std::sqrt(2.0) * sigma, 0.004);
}

TEST(TriangulateLinear, BadInputAndDegenerateGeometryAreReported) {
  const Rig rig = DefaultRig();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d p_S(0.2, 0.1, 4.0);
  const Eigen::Vector2d uv_l = *rig.left.intrinsics.Project(p_S);
  const Eigen::Vector2d uv_r = *rig.right.intrinsics.Project(rig.T_R_L * p_S);

  EXPECT_FALSE(TriangulateLinear(Eigen::Vector2d(nan, 1.0), uv_r, rig.left, rig.right, 0.3).ok);
  EXPECT_FALSE(
      TriangulateLinear(uv_l, Eigen::Vector2d(1.0, INFINITY), rig.left, rig.right, 0.3).ok);
  EXPECT_FALSE(TriangulateLinear(uv_l, uv_r, rig.left, rig.right, 0.0).ok);

  // A point at infinity: both rays parallel.
  const Eigen::Vector3d direction(0.1, -0.05, 1.0);
  const TriangulatedPoint parallel = TriangulateLinear(
      *rig.left.intrinsics.Project(direction),
      *rig.right.intrinsics.Project(rig.T_R_L.q * direction), rig.left, rig.right, 0.3);
  EXPECT_FALSE(parallel.ok);
  EXPECT_NE(parallel.reason.find("parallel"), std::string::npos) << parallel.reason;

  // Behind both cameras: the rays meet behind them.
  const Eigen::Vector3d behind(0.3, 0.2, -3.0);
  const TriangulatedPoint back = TriangulateLinear(
      PixelOf(rig.left.intrinsics, behind), PixelOf(rig.right.intrinsics, rig.T_R_L * behind),
      rig.left, rig.right, 0.3);
  EXPECT_FALSE(back.ok);
  EXPECT_NE(back.reason.find("behind"), std::string::npos) << back.reason;

  // Behind the right camera only: a rig whose right camera stands 5 m ahead of the left one.
  CameraCalibration ahead = rig.left;
  ahead.T_B_C = Pose3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 5.0));
  CameraCalibration origin = rig.left;
  origin.T_B_C = Pose3::Identity();
  const Eigen::Vector3d between(0.5, 0.2, 2.0);
  const TriangulatedPoint right_behind = TriangulateLinear(
      PixelOf(origin.intrinsics, between),
      PixelOf(ahead.intrinsics, between - Eigen::Vector3d(0, 0, 5.0)), origin, ahead, 0.3);
  EXPECT_FALSE(right_behind.ok);
  EXPECT_NE(right_behind.reason.find("behind the right"), std::string::npos) << right_behind.reason;
}

// ---------------------------------------------------------------------------------------------
// Matching detections of the dock lights rendered by the default rig.

struct StereoFrame {
  std::vector<LightDetection> left, right;
  std::vector<int> left_id, right_id;  // light id, -1 for a spurious detection
};

LightDetection Detection(const Eigen::Vector2d& uv, double radius_px) {
  LightDetection d;
  d.uv = uv;
  d.radius_px = radius_px;
  d.peak = 220.0;
  d.score = 1.0;
  return d;
}

// Lights seen by each camera of the pair from body pose T_D_B, radius f * r / z, with optional
// centroid noise.
StereoFrame RenderFrame(const Rig& rig, const DockModel& dock, const Pose3& T_D_B,
                        std::mt19937* rng = nullptr, double pixel_sigma = 0.0) {
  StereoFrame frame;
  std::normal_distribution<double> noise(0.0, 1.0);
  auto render = [&](const CameraCalibration& camera, std::vector<LightDetection>* detections,
                    std::vector<int>* ids) {
    const Pose3 T_C_D = (T_D_B * camera.T_B_C).Inverse();
    for (const DockLight& light : dock.lights) {
      const Eigen::Vector3d p_C = T_C_D * light.p_D;
      const auto uv = camera.intrinsics.Project(p_C);
      if (!uv || !camera.intrinsics.InImage(*uv, 2.0)) continue;
      Eigen::Vector2d measured = *uv;
      if (rng != nullptr) measured += pixel_sigma * Eigen::Vector2d(noise(*rng), noise(*rng));
      detections->push_back(Detection(measured, camera.intrinsics.fx() * light.radius_m / p_C.z()));
      ids->push_back(light.id);
    }
  };
  render(rig.left, &frame.left, &frame.left_id);
  render(rig.right, &frame.right, &frame.right_id);
  return frame;
}

void Shuffle(std::mt19937& rng, std::vector<LightDetection>* detections, std::vector<int>* ids) {
  std::vector<int> order(detections->size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<LightDetection> d;
  std::vector<int> id;
  for (int i : order) {
    d.push_back((*detections)[i]);
    id.push_back((*ids)[i]);
  }
  *detections = d;
  *ids = id;
}

struct MatchCount {
  int correct = 0;   // same light in both images
  int wrong = 0;     // a light paired with another light or with a spurious detection
  int expected = 0;  // lights detected in both images
};

MatchCount Check(const StereoFrame& frame, const std::vector<std::pair<int, int>>& matches) {
  MatchCount count;
  for (int id : frame.left_id) {
    if (id >= 0 && std::count(frame.right_id.begin(), frame.right_id.end(), id) > 0) {
      ++count.expected;
    }
  }
  std::vector<bool> left_used(frame.left.size(), false), right_used(frame.right.size(), false);
  for (const auto& [i, j] : matches) {
    EXPECT_FALSE(left_used[i]) << "left detection used twice";
    EXPECT_FALSE(right_used[j]) << "right detection used twice";
    left_used[i] = right_used[j] = true;
    const int a = frame.left_id[i], b = frame.right_id[j];
    if (a >= 0 && a == b) {
      ++count.correct;
    } else if (a >= 0 || b >= 0) {
      ++count.wrong;
    }
  }
  return count;
}

TEST(MatchStereoDetections, CleanDetectionsAlongTheDefaultTrajectoryAllMatch) {
  const Scenario scenario = test::DefaultScenario();
  const Rig rig = DefaultRig();
  const DockingTrajectory trajectory(scenario.trajectory);
  std::mt19937 rng(1);
  MatchCount total;
  int frames = 0;
  for (double t = 0.0; t <= scenario.duration_s; t += 0.25) {
    StereoFrame frame = RenderFrame(rig, scenario.dock, trajectory.At(t).T_D_B, &rng, 0.2);
    if (frame.left.empty() || frame.right.empty()) continue;
    Shuffle(rng, &frame.left, &frame.left_id);
    Shuffle(rng, &frame.right, &frame.right_id);
    const auto matches = MatchStereoDetections(frame.left, frame.right, rig.left, rig.right);
    const MatchCount count = Check(frame, matches);
    EXPECT_EQ(count.wrong, 0) << "t=" << t;
    EXPECT_EQ(count.correct, count.expected) << "t=" << t;
    total.correct += count.correct;
    total.expected += count.expected;
    ++frames;
  }
  std::printf("clean: %d frames with lights, %d of %d stereo pairs matched\n", frames,
              total.correct, total.expected);
  EXPECT_GT(total.expected, 200);
}

TEST(MatchStereoDetections, SpuriousDetectionsNeverCauseAWrongPair) {
  const Scenario scenario = test::DefaultScenario();
  const Rig rig = DefaultRig();
  const DockingTrajectory trajectory(scenario.trajectory);
  const PinholeRadtanCamera& cam = rig.left.intrinsics;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  MatchCount total;
  for (double t = 0.0; t <= scenario.duration_s; t += 0.25) {
    StereoFrame frame = RenderFrame(rig, scenario.dock, trajectory.At(t).T_D_B, &rng, 0.3);
    if (frame.left.empty() || frame.right.empty()) continue;
    // Random distractors (particles, reflections) in both images...
    for (int k = 0; k < 4; ++k) {
      frame.left.push_back(Detection(Eigen::Vector2d(u(rng) * cam.width(), u(rng) * cam.height()),
                                     1.0 + 8.0 * u(rng)));
      frame.left_id.push_back(-1);
      frame.right.push_back(Detection(Eigen::Vector2d(u(rng) * cam.width(), u(rng) * cam.height()),
                                      1.0 + 8.0 * u(rng)));
      frame.right_id.push_back(-1);
    }
    // ...and a twice-too-large blob on the epipolar line of a real light, at a plausible
    // disparity in the right image: the radius gate must reject it.
    for (size_t i = 0; i < frame.right.size(); ++i) {
      if (frame.right_id[i] < 0) continue;
      LightDetection big = frame.right[i];
      big.uv.x() -= 15.0;
      big.radius_px *= 2.5;
      frame.right.push_back(big);
      frame.right_id.push_back(-1);
      break;
    }
    Shuffle(rng, &frame.left, &frame.left_id);
    Shuffle(rng, &frame.right, &frame.right_id);
    const auto matches = MatchStereoDetections(frame.left, frame.right, rig.left, rig.right);
    const MatchCount count = Check(frame, matches);
    EXPECT_EQ(count.wrong, 0) << "t=" << t;
    total.correct += count.correct;
    total.expected += count.expected;
  }
  std::printf("with distractors: %d of %d stereo pairs matched, none wrong\n", total.correct,
              total.expected);
  EXPECT_GT(total.correct, 0.9 * total.expected);
}

// Level hover above the dock: the bar (lights 3, 4, 5 along D's y axis) is parallel to the
// baseline, so the three share one epipolar line and one radius. Only the order along the
// line tells them apart.
TEST(MatchStereoDetections, LightsOnALineParallelToTheBaselineUseTheOrdering) {
  const Scenario scenario = test::DefaultScenario();
  const Rig rig = DefaultRig();
  const Pose3 T_D_B(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-3.5, 0.0, -3.0));
  StereoFrame frame = RenderFrame(rig, scenario.dock, T_D_B);
  ASSERT_EQ(frame.left.size(), 6u);
  ASSERT_EQ(frame.right.size(), 6u);
  auto find = [](const std::vector<int>& ids, int id) {
    return static_cast<int>(std::find(ids.begin(), ids.end(), id) - ids.begin());
  };
  // They really share the line (same row, same radius).
  EXPECT_NEAR(frame.left[find(frame.left_id, 3)].uv.y(), frame.left[find(frame.left_id, 5)].uv.y(),
              1.0);
  EXPECT_NEAR(frame.left[find(frame.left_id, 3)].radius_px,
              frame.left[find(frame.left_id, 5)].radius_px, 1e-9);

  std::mt19937 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    StereoFrame shuffled = frame;
    Shuffle(rng, &shuffled.left, &shuffled.left_id);
    Shuffle(rng, &shuffled.right, &shuffled.right_id);
    const auto matches = MatchStereoDetections(shuffled.left, shuffled.right, rig.left, rig.right);
    const MatchCount count = Check(shuffled, matches);
    EXPECT_EQ(count.wrong, 0);
    EXPECT_EQ(count.correct, 6);
  }

  // A narrower bar (lights 0.1 m apart, less than the 0.25 m baseline): now even the crossed
  // pairs have positive disparity and a plausible depth, so the gates alone cannot decide.
  DockModel narrow = scenario.dock;
  for (DockLight& light : narrow.lights) {
    if (light.id == 3 || light.id == 5) light.p_D.y() *= 0.1 / 0.6;
  }
  const StereoFrame narrow_frame = RenderFrame(rig, narrow, T_D_B);
  for (int trial = 0; trial < 20; ++trial) {
    StereoFrame shuffled = narrow_frame;
    Shuffle(rng, &shuffled.left, &shuffled.left_id);
    Shuffle(rng, &shuffled.right, &shuffled.right_id);
    const auto matches = MatchStereoDetections(shuffled.left, shuffled.right, rig.left, rig.right);
    const MatchCount count = Check(shuffled, matches);
    EXPECT_EQ(count.wrong, 0);
    EXPECT_EQ(count.correct, 6);
  }

  // Without the right image of light 4, light 4 could take light 3's partner as well as
  // light 3 can: that pair is ambiguous and must be dropped, not guessed.
  StereoFrame missing = frame;
  const int r4 = find(missing.right_id, 4);
  missing.right.erase(missing.right.begin() + r4);
  missing.right_id.erase(missing.right_id.begin() + r4);
  const auto matches = MatchStereoDetections(missing.left, missing.right, rig.left, rig.right);
  const MatchCount count = Check(missing, matches);
  EXPECT_EQ(count.wrong, 0);
  EXPECT_GE(count.correct, 3);  // lights 0, 1, 2 are on other epipolar lines
  std::printf("bar light missing on the right: %d correct pairs of 5 possible, 0 wrong\n",
              count.correct);
}

TEST(MatchStereoDetections, GatesRejectImpossiblePairs) {
  const Rig rig = DefaultRig();
  const Eigen::Vector3d p_S(0.1, 0.2, 4.0);
  const Eigen::Vector2d uv_l = *rig.left.intrinsics.Project(p_S);
  const Eigen::Vector2d uv_r = *rig.right.intrinsics.Project(rig.T_R_L * p_S);
  const std::vector<LightDetection> left = {Detection(uv_l, 6.0)};

  auto match = [&](const LightDetection& right, const StereoMatchOptions& options = {}) {
    return MatchStereoDetections(left, {right}, rig.left, rig.right, options).size();
  };
  EXPECT_EQ(match(Detection(uv_r, 6.0)), 1u);
  EXPECT_EQ(match(Detection(uv_r + Eigen::Vector2d(0.0, 5.0), 6.0)), 0u);  // off the epipolar line
  EXPECT_EQ(match(Detection(uv_r, 12.0)), 0u);                             // radius ratio 2
  // Negative disparity, exactly on the epipolar line (the pair is rectified: same rotation,
  // baseline along x, so epipolar lines are rows of normalized coordinates).
  const Eigen::Vector2d xy_l = rig.left.intrinsics.Unproject(uv_l);
  const Eigen::Vector2d xy_r = rig.right.intrinsics.Unproject(uv_r);
  const Eigen::Vector2d uv_negative = rig.right.intrinsics.ProjectNormalized(
      xy_r + Eigen::Vector2d(2.0 * (xy_l.x() - xy_r.x()), 0.0));
  EXPECT_EQ(match(Detection(uv_negative, 6.0)), 0u);
  StereoMatchOptions near;
  near.max_depth_m = 3.0;
  EXPECT_EQ(match(Detection(uv_r, 6.0), near), 0u);  // beyond the depth range
  LightDetection nan_detection = Detection(uv_r, 6.0);
  nan_detection.uv.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(match(nan_detection), 0u);
  EXPECT_TRUE(MatchStereoDetections({}, {}, rig.left, rig.right).empty());
}

}  // namespace
}  // namespace auvdock
