// MatchByPrediction: labelling with a perturbed prediction over random views of the default
// dock with the default mono camera, and its refusals.
#include "auvdock/vision/tracking_matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
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

// The camera pose moved by exactly `position_m` in a random direction and rotated by exactly
// `angle_rad` about a random axis (a prediction error of that size).
Pose3 Perturb(const Pose3& T_C_D, double position_m, double angle_rad, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d direction =
      Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  Pose3 T_D_C = T_C_D.Inverse();
  T_D_C.p += position_m * direction;
  T_D_C.q = (ExpQuaternion(angle_rad * axis) * T_D_C.q).normalized();
  return T_D_C.Inverse();
}

enum class Outcome { kCorrect, kIncomplete, kRefused, kSilentlyWrong };

Outcome Classify(const MatchResult& result, const View& view) {
  if (result.status != MatchStatus::kOk) return Outcome::kRefused;
  for (const LightMatch& m : result.matches) {
    if (view.truth.at(m.detection) != m.light_id) return Outcome::kSilentlyWrong;
  }
  const size_t real = static_cast<size_t>(
      std::count_if(view.truth.begin(), view.truth.end(), [](int id) { return id >= 0; }));
  return result.matches.size() == real ? Outcome::kCorrect : Outcome::kIncomplete;
}

struct Counts {
  int views = 0, correct = 0, incomplete = 0, refused = 0, wrong = 0;
  double seconds = 0.0;
  void Add(Outcome o) {
    ++views;
    correct += o == Outcome::kCorrect;
    incomplete += o == Outcome::kIncomplete;
    refused += o == Outcome::kRefused;
    wrong += o == Outcome::kSilentlyWrong;
  }
  void Print(const std::string& label) const {
    std::printf(
        "%s: %d views: correct %.2f %%, incomplete %.2f %%, refused %.2f %%, silently "
        "wrong %.2f %%, %.1f us/frame\n",
        label.c_str(), views, 100.0 * correct / views, 100.0 * incomplete / views,
        100.0 * refused / views, 100.0 * wrong / views, 1e6 * seconds / views);
  }
};

Counts RunViews(const DockModel& dock, const PinholeRadtanCamera& camera, double position_m,
                double angle_rad, double gate_px, int num_visible, int num_spurious,
                uint64_t seed) {
  std::mt19937_64 rng(seed);
  Counts counts;
  for (int i = 0; i < 1000; ++i) {
    const Pose3 T_C_D = RandomView(dock, camera, 60.0 * kDeg, rng);
    std::vector<int> ids = test::AllLightIds(dock);
    std::shuffle(ids.begin(), ids.end(), rng);
    ids.resize(num_visible);
    const View view = MakeView(dock, camera, T_C_D, ids, num_spurious, 0.3, rng);
    const Pose3 predicted = Perturb(T_C_D, position_m, angle_rad, rng);
    const auto start = std::chrono::steady_clock::now();
    const MatchResult result = MatchByPrediction(view.detections, dock, camera, predicted, gate_px);
    counts.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    counts.Add(Classify(result, view));
  }
  return counts;
}

TEST(MatchByPrediction, PredictionOffByTwoCentimetresAndOneDegreeIsAlwaysCorrect) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  // 1 deg is ~8 px for this camera; 2 cm is ~5 px at 2 m. Gate 20 px.
  const Counts counts = RunViews(dock, camera, 0.02, 1.0 * kDeg, 20.0, 6, 0, 11);
  counts.Print("tracking, 6 of 6 lights, prediction off by 2 cm / 1 deg, gate 20 px");
  EXPECT_EQ(counts.correct, counts.views);
}

TEST(MatchByPrediction, OtherPredictionErrorsAndVisibility) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  struct Case {
    double position_m, angle_deg, gate_px;
    int visible, spurious;
  };
  for (const Case c : {Case{0.02, 1.0, 20.0, 4, 2}, Case{0.02, 1.0, 20.0, 6, 2},
                       Case{0.05, 3.0, 40.0, 6, 0}, Case{0.05, 3.0, 40.0, 4, 2}}) {
    const Counts counts = RunViews(dock, camera, c.position_m, c.angle_deg * kDeg, c.gate_px,
                                   c.visible, c.spurious, 12 + c.visible + c.spurious);
    char label[160];
    std::snprintf(label, sizeof(label),
                  "tracking, %d of 6 lights + %d spurious, prediction off by %.0f cm / %.0f deg, "
                  "gate %.0f px",
                  c.visible, c.spurious, 100 * c.position_m, c.angle_deg, c.gate_px);
    counts.Print(label);
    EXPECT_LE(counts.wrong, 0.01 * counts.views) << label;
  }
}

TEST(MatchByPrediction, ExactPredictionLabelsTheCentrelineDock) {
  // The collinear dock is degenerate for matching without a pose, not with a good prediction.
  const DockModel dock = LoadDock("centerline_8.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(5);
  Counts counts;
  for (int i = 0; i < 200; ++i) {
    const Pose3 T_C_D = RandomView(dock, camera, 30.0 * kDeg, rng);
    const View view = MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.3, rng);
    counts.Add(Classify(MatchByPrediction(view.detections, dock, camera,
                                          Perturb(T_C_D, 0.01, 0.3 * kDeg, rng), 20.0),
                        view));
  }
  counts.Print("tracking, centre-line dock, prediction off by 1 cm / 0.3 deg");
  EXPECT_EQ(counts.correct, counts.views);
}

TEST(MatchByPrediction, TwoLightsOnOneDetectionIsAmbiguous) {
  // A dock with a second light 5 mm from light 2: from 2-8 m both project within ~1 px of each
  // other, so their one detection cannot be labelled.
  DockModel dock = LoadDock("t_shape.yaml");
  DockLight twin = *dock.FindLight(2);
  twin.id = 9;
  twin.p_D += Eigen::Vector3d(0.005, 0.0, 0.0);
  dock.lights.push_back(twin);
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(21);
  for (int i = 0; i < 50; ++i) {
    const Pose3 T_C_D = RandomView(dock, camera, 30.0 * kDeg, rng);
    const View view = MakeView(dock, camera, T_C_D, {0, 1, 2, 3, 4, 5}, 0, 0.3, rng);
    const MatchResult result = MatchByPrediction(view.detections, dock, camera, T_C_D, 20.0);
    ASSERT_EQ(result.status, MatchStatus::kAmbiguous) << i;
    EXPECT_TRUE(result.reason.find("lights 2 and 9") != std::string::npos ||
                result.reason.find("lights 9 and 2") != std::string::npos)
        << result.reason;
    EXPECT_TRUE(result.matches.empty());
  }
}

TEST(MatchByPrediction, SpuriousDetectionNextToALightIsAmbiguous) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(22);
  const Pose3 T_C_D = RandomView(dock, camera, 20.0 * kDeg, rng);
  View view = MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.0, rng);
  LightDetection near = view.detections[0];
  near.uv += Eigen::Vector2d(0.4, 0.3);
  view.detections.push_back(near);
  const MatchResult result = MatchByPrediction(view.detections, dock, camera, T_C_D, 20.0);
  EXPECT_EQ(result.status, MatchStatus::kAmbiguous);
  EXPECT_FALSE(result.reason.empty());
  std::printf("tracking, spurious detection 0.5 px from a light: %s\n", result.reason.c_str());
}

// Every light mirrored 28 px below (a reflection on a pale deck): the offset that puts the
// lights on their reflections explains as many lights as the true one. A prediction 2-3 px off
// chooses the true labelling (it was refused before); never the mirror.
TEST(MatchByPrediction, MirroredLightsFarFromThePredictionDoNotMakeItAmbiguous) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(24);
  int chosen = 0, trials = 0;
  for (int i = 0; i < 40; ++i) {
    const Pose3 T_C_D = RandomView(dock, camera, 20.0 * kDeg, rng);
    View view = MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.2, rng);
    const size_t n = view.detections.size();
    bool inside = true;
    for (size_t j = 0; j < n; ++j) {
      LightDetection mirrored = view.detections[j];
      mirrored.uv.y() += 28.0;
      inside = inside && camera.InImage(mirrored.uv);
      view.detections.push_back(mirrored);
      view.truth.push_back(-1);
    }
    if (!inside) continue;
    ++trials;
    // The prediction shifted by ~2.5 px in the image: a rotation about the camera's x axis.
    Pose3 predicted = T_C_D;
    predicted.q = (ExpQuaternion(Eigen::Vector3d(2.5 / camera.fx(), 0.0, 0.0)) * T_C_D.q);
    predicted.q.normalize();
    predicted.p = ExpQuaternion(Eigen::Vector3d(2.5 / camera.fx(), 0.0, 0.0)) * T_C_D.p;
    const MatchResult result = MatchByPrediction(view.detections, dock, camera, predicted, 40.0);
    ASSERT_NE(Classify(result, view), Outcome::kSilentlyWrong) << i;
    chosen += Classify(result, view) == Outcome::kCorrect;

    TrackingMatcherOptions refuse;
    refuse.gate_px = 40.0;
    refuse.decisive_offset_ratio = 0.0;
    EXPECT_NE(MatchByPrediction(view.detections, dock, camera, predicted, refuse).status,
              MatchStatus::kOk)
        << i;
    // A prediction 9 px towards the mirror (19 px from it): no offset is decisively nearer, and
    // the rule changes nothing.
    auto turned = [&](double angle_rad) {
      Pose3 T = T_C_D;
      T.q = (ExpQuaternion(Eigen::Vector3d(angle_rad, 0.0, 0.0)) * T_C_D.q).normalized();
      T.p = ExpQuaternion(Eigen::Vector3d(angle_rad, 0.0, 0.0)) * T_C_D.p;
      return T;
    };
    // The sign that moves the projections down (+v), towards the mirror.
    const Eigen::Vector3d p_D = dock.lights.front().p_D;
    const double down = camera.Project(turned(9.0 / camera.fx()) * p_D)->y() -
                        camera.Project(T_C_D * p_D)->y();
    const Pose3 toward = turned((down > 0.0 ? 9.0 : -9.0) / camera.fx());
    const MatchResult with_rule = MatchByPrediction(view.detections, dock, camera, toward, 40.0);
    const MatchResult without = MatchByPrediction(view.detections, dock, camera, toward, refuse);
    EXPECT_EQ(with_rule.status, without.status) << i;
    EXPECT_EQ(with_rule.matches.size(), without.matches.size()) << i;
  }
  // The rest are refused: a labelling that takes one light's mirror and the others' lights lies
  // between the two offsets, within the ratio.
  std::printf("tracking, lights mirrored 28 px below, prediction 2.5 px off: %d of %d chosen\n",
              chosen, trials);
  ASSERT_GE(trials, 20);
  EXPECT_GE(chosen, 0.8 * trials);
}

TEST(MatchByPrediction, AShiftAlongTheStemThatExplainsOneSpuriousLightMoreIsNotTaken) {
  // The T's stem lights 0, 1, 2 and bar centre 4 are evenly spaced (0.5 m). The bar's lights are
  // missed; a spurious detection lies where light 3 would be with the whole pattern shifted one
  // spacing back along the stem. That shift explains 4 detections (0 as 1, 1 as 2, 2 as 4, the
  // spurious one as 3), the truth 3. The prediction is a pixel off: the shift lies a whole
  // spacing (8-40 px here) from it.
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(7);
  int trials = 0, taken_without_the_rule = 0;
  for (int i = 0; i < 60 && trials < 25; ++i) {
    const Pose3 T_C_D = RandomView(dock, camera, 30.0 * kDeg, rng);
    View view = MakeView(dock, camera, T_C_D, {0, 1, 2}, 0, 0.2, rng);
    const Eigen::Vector2d p0 = *camera.Project(T_C_D * dock.lights[0].p_D);
    const Eigen::Vector2d p1 = *camera.Project(T_C_D * dock.lights[1].p_D);
    const Eigen::Vector2d p3 = *camera.Project(T_C_D * dock.lights[3].p_D);
    const Eigen::Vector2d spacing = p1 - p0;
    if (spacing.norm() < 8.0 || spacing.norm() > 40.0) continue;
    LightDetection spurious = view.detections.front();
    spurious.uv = p3 - spacing;
    if (!camera.InImage(spurious.uv)) continue;
    view.detections.push_back(spurious);
    view.truth.push_back(-1);
    ++trials;
    Pose3 predicted = T_C_D;
    predicted.q = (ExpQuaternion(Eigen::Vector3d(1.0 / camera.fx(), 0.0, 0.0)) * T_C_D.q);
    predicted.q.normalize();
    const MatchResult result = MatchByPrediction(view.detections, dock, camera, predicted, 40.0);
    EXPECT_NE(Classify(result, view), Outcome::kSilentlyWrong) << i;
    // As the mono poser tracks: 4 matches at least (the 3 true ones are not enough to take).
    TrackingMatcherOptions four;
    four.gate_px = 40.0;
    four.min_matches = 4;
    EXPECT_NE(Classify(MatchByPrediction(view.detections, dock, camera, predicted, four), view),
              Outcome::kSilentlyWrong)
        << i;
    TrackingMatcherOptions without;
    without.gate_px = 40.0;
    without.decisive_offset_ratio = 0.0;
    taken_without_the_rule +=
        Classify(MatchByPrediction(view.detections, dock, camera, predicted, without), view) ==
        Outcome::kSilentlyWrong;
  }
  ASSERT_GE(trials, 15);
  // Without the rule the shifted pattern is taken: the case is real.
  EXPECT_GE(taken_without_the_rule, trials / 2);
}

TEST(MatchByPrediction, TooFewMatchesFail) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(23);
  const Pose3 T_C_D = RandomView(dock, camera, 20.0 * kDeg, rng);
  const View two = MakeView(dock, camera, T_C_D, {0, 5}, 0, 0.3, rng);
  EXPECT_EQ(MatchByPrediction(two.detections, dock, camera, T_C_D, 20.0).status,
            MatchStatus::kFailed);
  // All detections far from every prediction.
  View far = MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.3, rng);
  for (LightDetection& d : far.detections) d.uv += Eigen::Vector2d(150.0, 0.0);
  const MatchResult result = MatchByPrediction(far.detections, dock, camera, T_C_D, 20.0);
  EXPECT_EQ(result.status, MatchStatus::kFailed);
  EXPECT_FALSE(result.reason.empty());
}

}  // namespace
}  // namespace auvdock

namespace auvdock {
namespace {

// Four lights, one of them cut by the border: its centroid is biased by 6 px and says so in its
// covariance (sigma 6 px). Weighed by that covariance the four are one pose; with one noise for
// all they are not, and the frame has no labels (the real pool clip's frames 385-405).
TEST(MatchByPrediction, ADetectionWithAWideCovarianceWeighsLess) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(77);
  const Pose3 T_C_D = RandomView(dock, camera, 20.0 * kDeg, rng);
  std::normal_distribution<double> noise(0.0, 0.3);
  std::vector<LightDetection> detections;
  for (int index : {0, 2, 3, 5}) {
    LightDetection d;
    d.uv = *camera.Project(T_C_D * dock.lights[index].p_D) +
           Eigen::Vector2d(noise(rng), noise(rng));
    d.covariance = 0.09 * Eigen::Matrix2d::Identity();
    if (index == 5) {
      d.uv += Eigen::Vector2d(0.0, -6.0);
      d.covariance = 36.0 * Eigen::Matrix2d::Identity();
    }
    detections.push_back(d);
  }
  TrackingMatcherOptions options;
  options.gate_px = 20.0;
  options.min_matches = 4;
  const MatchResult weighed = MatchByPrediction(detections, dock, camera, T_C_D, options);
  ASSERT_EQ(weighed.status, MatchStatus::kOk) << weighed.reason;
  ASSERT_EQ(weighed.matches.size(), 4u);
  const std::vector<int> index_of_detection = {0, 2, 3, 5};
  for (const LightMatch& m : weighed.matches) {
    EXPECT_EQ(m.light_id, dock.lights[index_of_detection[m.detection]].id);
  }
  options.use_detection_covariance = false;
  const MatchResult one_noise = MatchByPrediction(detections, dock, camera, T_C_D, options);
  EXPECT_NE(one_noise.status, MatchStatus::kOk);
}

// The weights pull the refined pose towards the precise correspondences.
TEST(RefinePoseOnCorrespondences, WeightsFollowThePreciseCorrespondences) {
  const DockModel dock = LoadDock("t_shape.yaml");
  const PinholeRadtanCamera camera = DefaultMonoCamera();
  std::mt19937_64 rng(78);
  const Pose3 truth = RandomView(dock, camera, 20.0 * kDeg, rng);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> xy;
  for (const DockLight& light : dock.lights) {
    points.push_back(light.p_D);
    xy.push_back(camera.Unproject(*camera.Project(truth * light.p_D)));
  }
  xy[4] += Eigen::Vector2d(0.01, 0.0);  // ~5 px off
  std::vector<double> weights(points.size(), 1.0);
  weights[4] = 1e-6;
  Pose3 even = truth, weighed = truth;
  RefinePoseOnCorrespondences(points, xy, camera.fx(), camera.fy(), &even);
  RefinePoseOnCorrespondences(points, xy, camera.fx(), camera.fy(), &weighed, weights);
  EXPECT_GT((even.p - truth.p).norm(), 1e-3);
  EXPECT_LT((weighed.p - truth.p).norm(), 1e-5);
}

}  // namespace
}  // namespace auvdock
