// MatchOmnidirectional (seed 000's shape matcher): exact cases, refusals, and its success rate
// over random views of the default dock with the default mono camera, by camera tilt.
#include "auvdock/vision/omnidirectional_matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/io/dock_io.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/dock_views.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

using test::DefaultMonoCamera;
using test::LoadDock;
using test::MakeView;
using test::RandomView;
using test::View;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

bool AllCorrect(const MatchResult& result, const std::vector<int>& truth) {
  if (result.status != MatchStatus::kOk || result.matches.size() != truth.size()) return false;
  for (const LightMatch& m : result.matches) {
    if (truth.at(m.detection) != m.light_id) return false;
  }
  return true;
}

TEST(MatchOmnidirectional, ExactTopDownImagesAtAnyRotationScaleAndShift) {
  const DockModel dock = LoadDock("t_shape.yaml");
  for (double yaw_deg : {0.0, 37.0, 90.0, 135.0, 180.0, 211.0, 270.0, 359.0}) {
    // Image = rotated, scaled, shifted design (a pinhole looking straight down keeps handedness).
    const Eigen::Rotation2Dd rotation(yaw_deg * kDeg);
    std::vector<LightDetection> detections;
    std::vector<int> truth;
    for (int i = static_cast<int>(dock.lights.size()) - 1; i >= 0; --i) {  // reversed order
      LightDetection d;
      d.uv = Eigen::Vector2d(320.0, 256.0) + 87.0 * (rotation * dock.lights[i].p_D.head<2>());
      detections.push_back(d);
      truth.push_back(dock.lights[i].id);
    }
    const MatchResult result = MatchOmnidirectional(detections, dock);
    EXPECT_TRUE(AllCorrect(result, truth)) << "yaw " << yaw_deg << ": " << result.reason;
    EXPECT_NEAR(result.cost, 0.0, 1e-6);
  }
}

TEST(MatchOmnidirectional, RefusesWhatItCannotDo) {
  const DockModel dock = LoadDock("t_shape.yaml");
  std::vector<LightDetection> five(5);
  for (int i = 0; i < 5; ++i) five[i].uv = dock.lights[i].p_D.head<2>() * 100.0;
  const MatchResult missing = MatchOmnidirectional(five, dock);
  EXPECT_EQ(missing.status, MatchStatus::kFailed);
  EXPECT_FALSE(missing.reason.empty());
  EXPECT_TRUE(missing.matches.empty());

  DockModel two;
  two.lights = {dock.lights[0], dock.lights[3]};
  std::vector<LightDetection> two_detections(2);
  EXPECT_EQ(MatchOmnidirectional(two_detections, two).status, MatchStatus::kFailed);

  // Six detections that do not look like a T at all (a regular hexagon).
  std::vector<LightDetection> hexagon(6);
  for (int i = 0; i < 6; ++i) {
    hexagon[i].uv = 100.0 * Eigen::Vector2d(std::cos(i * 60.0 * kDeg), std::sin(i * 60.0 * kDeg));
  }
  EXPECT_NE(MatchOmnidirectional(hexagon, dock).status, MatchStatus::kOk);
}

TEST(MatchOmnidirectional, SymmetricLayoutsAreAmbiguous) {
  // Seed 001's centre line maps onto itself under 180 deg; a square under 90 deg.
  const DockModel centreline = LoadDock("centerline_8.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(31);
  int refused = 0;
  const int views = 1000;
  for (int i = 0; i < views; ++i) {
    const View view = MakeView(centreline, camera, RandomView(centreline, camera, 60.0 * kDeg, rng),
                               test::AllLightIds(centreline), 0, 0.3, rng);
    refused += MatchOmnidirectional(view.detections, centreline).status != MatchStatus::kOk;
  }
  std::printf("omnidirectional, centre-line dock: %d of %d views refused\n", refused, views);
  EXPECT_EQ(refused, views);

  DockModel square;
  for (int i = 0; i < 4; ++i) {
    DockLight light;
    light.id = i;
    light.p_D = Eigen::Vector3d(i % 2 ? 0.5 : -0.5, i / 2 ? 0.5 : -0.5, 0.0);
    square.lights.push_back(light);
  }
  std::vector<LightDetection> detections(4);
  for (int i = 0; i < 4; ++i) detections[i].uv = 200.0 * square.lights[i].p_D.head<2>();
  const MatchResult result = MatchOmnidirectional(detections, square);
  EXPECT_EQ(result.status, MatchStatus::kAmbiguous);
  EXPECT_NE(result.reason.find("90 deg"), std::string::npos) << result.reason;
}

// The paper's method is 2-D: it matches the image to the design up to rotation and scale, which
// perspective breaks. Measured over the random views of the default dock (all 6 lights visible,
// 0.3 px noise), by the range of the camera's roll and pitch away from straight down.
TEST(MatchOmnidirectional, SuccessRateByCameraTilt) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(4242);
  for (double max_tilt_deg : {5.0, 15.0, 30.0, 45.0, 60.0}) {
    int correct = 0, refused = 0, wrong = 0;
    const int views = 1000;
    double seconds = 0.0;
    for (int i = 0; i < views; ++i) {
      const View view = MakeView(dock, camera, RandomView(dock, camera, max_tilt_deg * kDeg, rng),
                                 test::AllLightIds(dock), 0, 0.3, rng);
      const auto start = std::chrono::steady_clock::now();
      const MatchResult result = MatchOmnidirectional(view.detections, dock);
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (AllCorrect(result, view.truth)) {
        ++correct;
      } else if (result.status == MatchStatus::kOk) {
        ++wrong;
      } else {
        ++refused;
      }
    }
    std::printf(
        "omnidirectional, roll/pitch within +-%2.0f deg: %d views: correct %.1f %%, "
        "refused %.1f %%, silently wrong %.1f %%, %.1f us/frame\n",
        max_tilt_deg, views, 100.0 * correct / views, 100.0 * refused / views,
        100.0 * wrong / views, 1e6 * seconds / views);
    if (max_tilt_deg <= 15.0) {
      EXPECT_EQ(correct, views) << "near top-down, +-" << max_tilt_deg << " deg";
    }
  }
}

}  // namespace
}  // namespace auvdock
