// MatchRansac on symmetric docks (ring of 8: 4-fold; corners + raised centre: 2-fold): a pose is
// given in every view (not "ambiguous"), the labels are right up to the symmetry, every rival
// pose is listed, and a hint (prediction, gravity, approach side) picks the true copy.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "auvdock/geometry/dock_symmetry.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/vision/ransac_matcher.h"
#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// The symmetry (index into symmetries) that maps the truth labels onto the matcher's, or -1.
int LabelsUpToSymmetry(const RansacMatchResult& r, const test::View& view, const DockModel& dock,
                       const std::vector<DockSymmetry>& symmetries) {
  auto index_of = [&](int id) {
    for (size_t i = 0; i < dock.lights.size(); ++i) {
      if (dock.lights[i].id == id) return static_cast<int>(i);
    }
    return -1;
  };
  for (size_t k = 0; k < symmetries.size(); ++k) {
    bool all = !r.matches.empty();
    for (const LightMatch& m : r.matches) {
      const int truth = view.truth.at(m.detection);
      all = all && truth >= 0 &&
            symmetries[k].permutation[index_of(truth)] == index_of(m.light_id);
    }
    if (all) return static_cast<int>(k);
  }
  return -1;
}

struct Counts {
  int views = 0, ok = 0, right_up_to_symmetry = 0, right_copy = 0;
};

// num_visible > 0: only that many consecutive lights (by id order) are in the image, as when a
// ring leaves the image's side.
Counts RunViews(const std::string& dock_file, int num_views, int num_spurious, bool give_prediction,
           bool give_gravity, int num_visible = 0) {
  const DockModel dock = test::LoadDock(dock_file);
  const auto symmetries = FindDockSymmetries(dock);
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  std::mt19937_64 rng(7);
  RansacMatcherOptions options;
  Counts c;
  for (int v = 0; v < num_views; ++v) {
    const Pose3 T_C_D = test::RandomView(dock, camera, 25 * kDeg, rng);
    std::vector<int> visible = test::AllLightIds(dock);
    if (num_visible > 0) {
      std::rotate(visible.begin(), visible.begin() + v % visible.size(), visible.end());
      visible.resize(num_visible);
    }
    const test::View view = test::MakeView(dock, camera, T_C_D, visible, num_spurious, 0.3, rng);
    SymmetryHint hint;
    if (give_prediction) {
      // A prediction a couple of degrees and centimetres off, as tracking gives.
      const Eigen::Vector3d d_theta(1.5 * kDeg, -1.0 * kDeg, 2.0 * kDeg);
      hint.predicted_T_C_D =
          Pose3(ExpQuaternion(d_theta) * T_C_D.q, T_C_D.p + Eigen::Vector3d(0.03, -0.02, 0.05));
    }
    if (give_gravity) hint.gravity_C = T_C_D.R() * dock.gravity_D;
    const RansacMatchResult r = MatchRansac(view.detections, dock, camera, options, rng, hint);
    ++c.views;
    if (r.status != MatchStatus::kOk) continue;
    ++c.ok;
    EXPECT_EQ(r.symmetric_T_C_D.size(), symmetries.size() - 1);
    EXPECT_EQ(r.symmetry.empty(), symmetries.size() == 1);
    const int k = LabelsUpToSymmetry(r, view, dock, symmetries);
    if (k >= 0) ++c.right_up_to_symmetry;
    if (k == 0) ++c.right_copy;
  }
  return c;
}

TEST(RansacSymmetricDock, RingGivesAPoseUpToItsSymmetry) {
  const Counts c = RunViews("ring_8.yaml", 60, 0, false, false);
  EXPECT_GE(c.ok, 57);  // >= 95 %: a symmetric dock is no reason to refuse
  EXPECT_EQ(c.right_up_to_symmetry, c.ok);
}

// Part of the ring in view: the labellings of a hypothesis's symmetric copies are one
// hypothesis, never rivals ("two labellings explain ..." with labels a quarter turn apart).
TEST(RansacSymmetricDock, PartOfTheRingGivesAPoseNotRivalCopies) {
  for (const int visible : {5, 6}) {
    const Counts c = RunViews("ring_8.yaml", 40, 3, false, false, visible);
    EXPECT_GE(c.ok, 36) << visible << " lights in view";
    EXPECT_EQ(c.right_up_to_symmetry, c.ok);
  }
}

TEST(RansacSymmetricDock, RingWithSpuriousDetections) {
  const Counts c = RunViews("ring_8.yaml", 40, 2, false, false);
  EXPECT_GE(c.ok, 34);
  EXPECT_EQ(c.right_up_to_symmetry, c.ok);
}

TEST(RansacSymmetricDock, PredictionPicksTheTrueCopy) {
  const Counts c = RunViews("ring_8.yaml", 40, 0, true, false);
  EXPECT_GE(c.ok, 38);
  EXPECT_EQ(c.right_copy, c.ok);
}

TEST(RansacSymmetricDock, GravityPicksTheTrueCopyOfAnUprightRing) {
  // The ring stood upright (gravity along +y of D, as on the pool docks): a turn about its axis
  // changes where gravity points in the camera, so gravity alone resolves the symmetry.
  DockModel dock = test::LoadDock("ring_8.yaml");
  dock.gravity_D = Eigen::Vector3d(0.0, 9.81, 0.0);
  const auto symmetries = FindDockSymmetries(dock);
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  std::mt19937_64 rng(11);
  int ok = 0, right = 0;
  for (int v = 0; v < 30; ++v) {
    const Pose3 T_C_D = test::RandomView(dock, camera, 25 * kDeg, rng);
    const test::View view =
        test::MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.3, rng);
    SymmetryHint hint;
    hint.gravity_C = T_C_D.R() * dock.gravity_D + Eigen::Vector3d(0.5, -0.3, 0.2);  // ~3 deg
    const RansacMatchResult r = MatchRansac(view.detections, dock, camera, {}, rng, hint);
    if (r.status != MatchStatus::kOk) continue;
    ++ok;
    right += LabelsUpToSymmetry(r, view, dock, symmetries) == 0;
    EXPECT_NE(r.symmetry.find("gravity"), std::string::npos) << r.symmetry;
  }
  EXPECT_GE(ok, 28);
  EXPECT_EQ(right, ok);
}

TEST(RansacSymmetricDock, GravityCannotResolveAFlatDockTurnedAboutTheVertical) {
  // Corners + raised centre: the 180-degree turn is about gravity, so gravity says nothing and
  // the result says the symmetry is unresolved; the approach side then decides.
  const DockModel dock = test::LoadDock("corners_centre_5.yaml");
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  std::mt19937_64 rng(5);
  int ok = 0, unresolved = 0, right_by_side = 0, ok_by_side = 0;
  const auto symmetries = FindDockSymmetries(dock);
  for (int v = 0; v < 30; ++v) {
    const Pose3 T_C_D = test::RandomView(dock, camera, 25 * kDeg, rng);
    const test::View view =
        test::MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.3, rng);
    SymmetryHint hint;
    hint.gravity_C = T_C_D.R() * dock.gravity_D;
    const RansacMatchResult r = MatchRansac(view.detections, dock, camera, {}, rng, hint);
    if (r.status == MatchStatus::kOk) {
      ++ok;
      unresolved += r.symmetry.find("unresolved") != std::string::npos;
      EXPECT_EQ(r.symmetry_unresolved, r.symmetry.find("unresolved") != std::string::npos);
    }
    // The camera centre's side of the dock, as an approach direction (horizontal, in D).
    const Eigen::Vector3d centre_D = T_C_D.Inverse().p;
    if (std::hypot(centre_D.x(), centre_D.y()) < 0.2) continue;  // overhead: no side
    // Where the vehicle comes from, 30 degrees off its true bearing.
    const double c30 = std::cos(30 * kDeg), s30 = std::sin(30 * kDeg);
    hint.approach_direction_D = Eigen::Vector3d(c30 * centre_D.x() - s30 * centre_D.y(),
                                                s30 * centre_D.x() + c30 * centre_D.y(), -1.0);
    const RansacMatchResult s = MatchRansac(view.detections, dock, camera, {}, rng, hint);
    if (s.status != MatchStatus::kOk) continue;
    ++ok_by_side;
    right_by_side += LabelsUpToSymmetry(s, view, dock, symmetries) == 0;
  }
  EXPECT_GE(ok, 28);
  EXPECT_EQ(unresolved, ok);
  EXPECT_GE(ok_by_side, 10);
  EXPECT_EQ(right_by_side, ok_by_side);
}

TEST(RansacSymmetricDock, AnAcousticFixPicksTheTrueCopyAndAnOutlierTellsNothing) {
  // The ring flat on the deck (its turns are about gravity): a USBL fix of a transponder 0.3 m
  // behind the camera tells the copies apart; a fix 5 m off fits no copy and decides nothing.
  const DockModel dock = test::LoadDock("ring_8.yaml");
  const auto symmetries = FindDockSymmetries(dock);
  const PinholeRadtanCamera camera = test::DefaultMonoCamera();
  std::mt19937_64 rng(13);
  std::normal_distribution<double> noise(0.0, 0.05);
  const Pose3 T_C_S(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1, -0.2, -0.3));
  int ok = 0, right = 0, by_fix = 0, outlier_ok = 0, outlier_unresolved = 0;
  for (int v = 0; v < 40; ++v) {
    const Pose3 T_C_D = test::RandomView(dock, camera, 25 * kDeg, rng);
    const test::View view =
        test::MakeView(dock, camera, T_C_D, test::AllLightIds(dock), 0, 0.3, rng);
    SymmetryHint hint;
    hint.gravity_C = T_C_D.R() * dock.gravity_D;
    hint.T_C_S = T_C_S;
    hint.fix_sigma_m = 0.05;
    const Eigen::Vector3d transponder_D = T_C_D.Inverse() * T_C_S.p;
    // Within 0.3 m of the ring's axis the copies put the transponder within 0.42 m of each
    // other: a 5 cm fix no longer tells them apart with certainty (it may, or stay unresolved).
    if (std::hypot(transponder_D.x(), transponder_D.y()) < 0.3) continue;
    const Eigen::Vector3d fix_D =
        transponder_D + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    hint.fix_p_D = fix_D;
    const RansacMatchResult r = MatchRansac(view.detections, dock, camera, {}, rng, hint);
    if (r.status == MatchStatus::kOk) {
      ++ok;
      right += LabelsUpToSymmetry(r, view, dock, symmetries) == 0;
      by_fix += r.symmetry.find("acoustic fix") != std::string::npos;
      EXPECT_FALSE(r.symmetry_unresolved) << r.symmetry << " d=" << std::hypot(transponder_D.x(), transponder_D.y());
    }
    hint.fix_p_D = fix_D + Eigen::Vector3d(5.0, 0.0, 0.0);
    const RansacMatchResult o = MatchRansac(view.detections, dock, camera, {}, rng, hint);
    if (o.status != MatchStatus::kOk) continue;
    ++outlier_ok;
    outlier_unresolved += o.symmetry_unresolved;
    EXPECT_NE(o.symmetry.find("unresolved"), std::string::npos) << o.symmetry;
  }
  EXPECT_GE(ok, 20);
  EXPECT_EQ(right, ok);
  EXPECT_EQ(by_fix, ok);
  EXPECT_EQ(outlier_ok, ok);
  EXPECT_EQ(outlier_unresolved, outlier_ok);
}

TEST(RansacSymmetricDock, TDockIsUnaffected) {
  const Counts c = RunViews("t_shape.yaml", 40, 0, false, false);
  EXPECT_EQ(c.ok, c.views);
  EXPECT_EQ(c.right_copy, c.ok);
}

}  // namespace
}  // namespace auvdock
