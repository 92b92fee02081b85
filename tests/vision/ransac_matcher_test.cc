// MatchRansac: P3P, and the matching requirements measured over random views of the default
// (T-shaped) and the centre-line dock with the default mono camera (cam2: 640x512, 70 deg HFOV,
// default distortion), 0.3 px centroid noise.
#include "auvdock/vision/ransac_matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <random>
#include <string>

#include <gtest/gtest.h>

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

enum class Outcome { kCorrect, kIncomplete, kRefused, kSilentlyWrong };

// kCorrect: kOk, every real detection labelled right, no spurious one labelled.
// kSilentlyWrong: kOk with any wrong label (a spurious detection labelled counts as wrong).
Outcome Classify(const MatchResult& result, const View& view) {
  if (result.status != MatchStatus::kOk) return Outcome::kRefused;
  int right = 0;
  for (const LightMatch& m : result.matches) {
    if (view.truth.at(m.detection) != m.light_id) return Outcome::kSilentlyWrong;
    ++right;
  }
  const int real = static_cast<int>(
      std::count_if(view.truth.begin(), view.truth.end(), [](int id) { return id >= 0; }));
  return right == real ? Outcome::kCorrect : Outcome::kIncomplete;
}

struct Tally {
  int views = 0;
  int correct = 0;
  int incomplete = 0;
  int refused = 0;
  int wrong = 0;
  std::map<std::string, int> reasons;
  double seconds = 0.0;

  void Add(Outcome outcome, const MatchResult& result) {
    ++views;
    correct += outcome == Outcome::kCorrect;
    incomplete += outcome == Outcome::kIncomplete;
    refused += outcome == Outcome::kRefused;
    wrong += outcome == Outcome::kSilentlyWrong;
    if (outcome == Outcome::kRefused) {
      // Group reasons by their first words.
      ++reasons[std::string(MatchStatusName(result.status)) + ": " +
                result.reason.substr(0, result.reason.find_first_of(":(0123456789"))];
    }
  }
  double Rate(int n) const { return views > 0 ? 100.0 * n / views : 0.0; }
  void Print(const char* label) const {
    std::printf(
        "%s: %d views: correct %.2f %%, incomplete %.2f %%, refused %.2f %%, "
        "silently wrong %.2f %%, %.1f us/frame\n",
        label, views, Rate(correct), Rate(incomplete), Rate(refused), Rate(wrong),
        views > 0 ? 1e6 * seconds / views : 0.0);
    for (const auto& [reason, count] : reasons)
      std::printf("    %5d x %s\n", count, reason.c_str());
  }
};

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(SolveP3P, RecoversRandomPoses) {
  // Includes many near-frontal configurations with similar depths, where Grunert's quartic has
  // four nearly equal roots and needs the Newton polishing.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int solved = 0;
  const int trials = 2000;
  for (int trial = 0; trial < trials; ++trial) {
    const Pose3 T_C_D(ExpQuaternion(Eigen::Vector3d(unit(rng), unit(rng), unit(rng))),
                      Eigen::Vector3d(0.5 * unit(rng), 0.5 * unit(rng), 5.0 + 2.0 * unit(rng)));
    std::array<Eigen::Vector3d, 3> X, f;
    for (int i = 0; i < 3; ++i) {
      X[i] = Eigen::Vector3d(unit(rng), unit(rng), 0.3 * unit(rng));
      f[i] = (T_C_D * X[i]).normalized();
    }
    double best = 1e9;
    for (const Pose3& pose : SolveP3P(f, X)) {
      best = std::min(best, (pose.p - T_C_D.p).norm() + RotationAngleBetween(pose.q, T_C_D.q));
      for (int i = 0; i < 3; ++i) {  // every solution is exact
        EXPECT_NEAR((pose * X[i]).normalized().dot(f[i]), 1.0, 1e-9);
      }
    }
    solved += best < 1e-6;
  }
  std::printf("P3P: true pose among the solutions in %d of %d random problems\n", solved, trials);
  EXPECT_GE(solved, trials - 2);
}

// Runs MatchRansac over random views with the given numbers of visible lights and spurious
// detections. classify_visible (optional) picks the tally of a draw from its visible lights.
void RunScenario(const DockModel& dock, const PinholeRadtanCamera& camera, int num_visible,
                 int num_spurious, int num_views, uint64_t seed,
                 const std::function<Tally*(const std::vector<int>&)>& tally_of) {
  std::mt19937_64 rng(seed);
  const RansacMatcherOptions options;
  for (int i = 0; i < num_views; ++i) {
    const Pose3 T_C_D = RandomView(dock, camera, 60.0 * kDeg, rng);
    std::vector<int> ids = test::AllLightIds(dock);
    std::shuffle(ids.begin(), ids.end(), rng);
    ids.resize(num_visible);
    const View view = MakeView(dock, camera, T_C_D, ids, num_spurious, 0.3, rng);
    const auto start = std::chrono::steady_clock::now();
    const RansacMatchResult result = MatchRansac(view.detections, dock, camera, options, rng);
    Tally* tally = tally_of(ids);
    tally->seconds += Seconds(start);
    tally->Add(Classify(result, view), result);
  }
}

TEST(MatchRansac, AllLightsVisibleIsAlwaysCorrect) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(1001);
  const RansacMatcherOptions options;
  Tally tally;
  std::vector<double> position_errors, angle_errors;
  for (int i = 0; i < 2000; ++i) {
    const View view = MakeView(dock, camera, RandomView(dock, camera, 60.0 * kDeg, rng),
                               test::AllLightIds(dock), 0, 0.3, rng);
    const auto start = std::chrono::steady_clock::now();
    const RansacMatchResult result = MatchRansac(view.detections, dock, camera, options, rng);
    tally.seconds += Seconds(start);
    const Outcome outcome = Classify(result, view);
    tally.Add(outcome, result);
    if (outcome == Outcome::kCorrect) {
      ASSERT_TRUE(result.T_C_D.has_value());
      position_errors.push_back((result.T_C_D->p - view.T_C_D.p).norm());
      angle_errors.push_back(RotationAngleBetween(result.T_C_D->q, view.T_C_D.q) / kDeg);
    }
  }
  tally.Print("ransac, 6 of 6 lights, 0.3 px");
  auto percentile = [](std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[static_cast<size_t>(p * (v.size() - 1))];
  };
  std::printf(
      "    verified pose T_C_D (views at 2-8 m): position error median %.3f / p99 %.3f / "
      "max %.3f m, rotation error median %.2f / p99 %.2f / max %.2f deg\n",
      percentile(position_errors, 0.5), percentile(position_errors, 0.99),
      percentile(position_errors, 1.0), percentile(angle_errors, 0.5),
      percentile(angle_errors, 0.99), percentile(angle_errors, 1.0));
  EXPECT_EQ(tally.correct, tally.views);
}

// The requirement "2 missing + 2 spurious: >= 99 % correct" cannot be met with the T layout, and
// this test documents why instead of asserting it. Of the 15 possible sets of 4 visible lights,
// 11 contain three collinear lights (on the stem or the bar) plus one off their line: a
// collinear triple maps onto any other collinear triple under some perspective tilt, and the
// single off-line light then leaves one redundant constraint, so other labellings fit as well
// as the truth (often to 0.05 px), with or without the spurious detections. One set is the
// collinear stem alone (its ends cannot be told apart). Only the 3 sets with both bar ends and
// two stem lights are in general position; there the truth is separable from rivals in most
// views, but at long range a rival labelling involving a spurious detection can still fit
// within a likelihood ratio of e^4.5. What is asserted: never more than 1 % silently wrong,
// and a floor on the correct rate of the general-position sets.
TEST(MatchRansac, TwoMissingTwoSpurious) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  Tally general, three_collinear, stem;
  auto tally_of = [&](const std::vector<int>& ids) -> Tally* {
    DockModel visible;
    for (int id : ids) visible.lights.push_back(*dock.FindLight(id));
    if (visible.LightsCollinear(1e-6)) return &stem;
    for (size_t drop = 0; drop < ids.size(); ++drop) {
      DockModel triple;
      for (size_t k = 0; k < ids.size(); ++k) {
        if (k != drop) triple.lights.push_back(visible.lights[k]);
      }
      if (triple.LightsCollinear(1e-6)) return &three_collinear;
    }
    return &general;
  };
  RunScenario(dock, camera, 4, 2, 3000, 2002, tally_of);
  general.Print("ransac, 4 of 6 lights in general position + 2 spurious");
  three_collinear.Print("ransac, 4 of 6 lights, 3 of them collinear + 2 spurious");
  stem.Print("ransac, 4 of 6 lights = the collinear stem + 2 spurious");
  const int views = general.views + three_collinear.views + stem.views;
  const int correct = general.correct + three_collinear.correct + stem.correct;
  const int wrong = general.wrong + three_collinear.wrong + stem.wrong;
  std::printf("    all %d draws: correct %.2f %%, silently wrong %.2f %%\n", views,
              100.0 * correct / views, 100.0 * wrong / views);
  EXPECT_LE(wrong, 0.01 * views);
  EXPECT_LE(general.wrong, 0.01 * general.views);
  EXPECT_GE(general.correct, 0.8 * general.views);
}

TEST(MatchRansac, OtherVisibilityMixes) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  struct Mix {
    int visible;
    int spurious;
  };
  for (const Mix mix : {Mix{6, 2}, Mix{5, 0}, Mix{5, 2}, Mix{4, 0}}) {
    Tally tally;
    RunScenario(dock, camera, mix.visible, mix.spurious, 1000, 7000 + mix.visible + mix.spurious,
                [&](const std::vector<int>&) { return &tally; });
    const std::string label = "ransac, " + std::to_string(mix.visible) + " of 6 lights + " +
                              std::to_string(mix.spurious) + " spurious";
    tally.Print(label.c_str());
    EXPECT_LE(tally.wrong, 0.01 * tally.views) << label;
    if (mix.visible == 6) {
      EXPECT_GE(tally.correct, 0.99 * tally.views) << label;
    }
  }
}

TEST(MatchRansac, CentrelineDockIsNeverLabelled) {
  const DockModel dock = LoadDock("centerline_8.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(3003);
  const RansacMatcherOptions options;
  Tally tally;
  for (int i = 0; i < 1000; ++i) {
    const View view = MakeView(dock, camera, RandomView(dock, camera, 60.0 * kDeg, rng),
                               test::AllLightIds(dock), i % 3, 0.3, rng);
    const RansacMatchResult result = MatchRansac(view.detections, dock, camera, options, rng);
    tally.Add(Classify(result, view), result);
  }
  tally.Print("ransac, centre-line dock (8 collinear lights)");
  EXPECT_GE(tally.refused, 0.99 * tally.views);
  EXPECT_LE(tally.wrong, 0.01 * tally.views);
}

TEST(MatchRansac, StemOfTheTAloneIsRefused) {
  // Only the four collinear stem lights of the T: the two ends are indistinguishable. With one
  // spurious detection, it can play the off-line "keystone" light: a labelling then fits in a
  // few percent of the views (2 % measured with require_redundant_support = false).
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(4004);
  for (int spurious : {0, 1}) {
    Tally tally;
    for (int i = 0; i < 1000; ++i) {
      const View view = MakeView(dock, camera, RandomView(dock, camera, 60.0 * kDeg, rng),
                                 {0, 1, 2, 4}, spurious, 0.3, rng);
      const RansacMatchResult result = MatchRansac(view.detections, dock, camera, {}, rng);
      tally.Add(Classify(result, view), result);
    }
    const std::string label =
        "ransac, the T's collinear stem alone + " + std::to_string(spurious) + " spurious";
    tally.Print(label.c_str());
    EXPECT_EQ(tally.correct, 0) << label;
    EXPECT_LE(tally.wrong, 0.01 * tally.views) << label;
  }
}

TEST(MatchRansac, VerifiedPoseAndReportedFigures) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(5005);
  const Pose3 T_C_D = RandomView(dock, camera, 30.0 * kDeg, rng);
  const View view = MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 1, 0.0, rng);
  const RansacMatchResult result = MatchRansac(view.detections, dock, camera, {}, rng);
  ASSERT_EQ(result.status, MatchStatus::kOk) << result.reason;
  EXPECT_EQ(Classify(result, view), Outcome::kCorrect);
  ASSERT_TRUE(result.T_C_D.has_value());
  EXPECT_LT((result.T_C_D->p - T_C_D.p).norm(), 1e-6);
  EXPECT_LT(RotationAngleBetween(result.T_C_D->q, T_C_D.q), 1e-6);
  EXPECT_LT(result.cost, 1e-3);
  EXPECT_EQ(result.num_inliers, 6);
  EXPECT_GT(result.num_p3p, 0);
}

// The camera 5 m from the T dock's centre at `elevation` above the deck, looking at it.
Pose3 ViewFromElevation(const DockModel& dock, double elevation_rad, double azimuth_rad) {
  return test::ViewFromElevation(dock, 5.0, elevation_rad, azimuth_rad);
}

// Seen edge-on the lights lie on one image line, where clutter lines up too (a cable, a rim, a
// light's beam): a pose less than min_view_elevation_deg above the deck is not accepted.
TEST(MatchRansac, AnEdgeOnViewOfThePlanarDockIsNotAPose) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(7007);
  RansacMatcherOptions off;
  off.min_view_elevation_deg = 0.0;
  int accepted_without = 0;
  for (int k = 0; k < 10; ++k) {
    const double azimuth = (20.0 + 7.0 * k) * kDeg;
    const View edge_on = MakeView(dock, camera, ViewFromElevation(dock, 2.5 * kDeg, azimuth),
                                  test::AllLightIds(dock), 0, 0.3, rng);
    const RansacMatchResult refused = MatchRansac(edge_on.detections, dock, camera, {}, rng);
    EXPECT_NE(refused.status, MatchStatus::kOk) << k;
    accepted_without +=
        MatchRansac(edge_on.detections, dock, camera, off, rng).status == MatchStatus::kOk;
    const View above = MakeView(dock, camera, ViewFromElevation(dock, 20.0 * kDeg, azimuth),
                                test::AllLightIds(dock), 0, 0.3, rng);
    const RansacMatchResult posed = MatchRansac(above.detections, dock, camera, {}, rng);
    ASSERT_EQ(posed.status, MatchStatus::kOk) << k << ": " << posed.reason;
    EXPECT_EQ(Classify(posed, above), Outcome::kCorrect) << k;
  }
  // Without the limit the edge-on views do give poses: the limit is what refuses them.
  EXPECT_GT(accepted_without, 0);
}

// The same test for a pose from elsewhere (tracking, a refinement): the limits apply to where the
// camera is, whatever it looks at.
TEST(CameraAboveTheDeck, OnlyViewsFromWellAboveTheDeckPass) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const RansacMatcherOptions options;  // 5 deg, 0.05 m
  for (double azimuth : {0.0, 70.0, 200.0}) {
    EXPECT_TRUE(CameraAboveTheDeck(dock, ViewFromElevation(dock, 20.0 * kDeg, azimuth * kDeg),
                                   options));
    EXPECT_TRUE(CameraAboveTheDeck(dock, ViewFromElevation(dock, 5.5 * kDeg, azimuth * kDeg),
                                   options));
    EXPECT_FALSE(CameraAboveTheDeck(dock, ViewFromElevation(dock, 4.5 * kDeg, azimuth * kDeg),
                                    options));
    EXPECT_FALSE(CameraAboveTheDeck(dock, ViewFromElevation(dock, -10.0 * kDeg, azimuth * kDeg),
                                    options));
  }
  RansacMatcherOptions off;
  off.min_view_elevation_deg = 0.0;
  EXPECT_TRUE(CameraAboveTheDeck(dock, ViewFromElevation(dock, 1.0 * kDeg, 0.0), off));
  EXPECT_FALSE(CameraAboveTheDeck(dock, ViewFromElevation(dock, -1.0 * kDeg, 0.0), off));
}

TEST(MatchRansac, TooFewDetectionsFail) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(6006);
  const View view =
      MakeView(dock, camera, RandomView(dock, camera, 30.0 * kDeg, rng), {0, 3, 5}, 0, 0.3, rng);
  const RansacMatchResult result = MatchRansac(view.detections, dock, camera, {}, rng);
  EXPECT_EQ(result.status, MatchStatus::kFailed);
  EXPECT_FALSE(result.reason.empty());
  EXPECT_FALSE(result.T_C_D.has_value());
  EXPECT_TRUE(result.matches.empty());
}

}  // namespace
}  // namespace auvdock
