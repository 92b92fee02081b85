// FindDockSymmetries on the shipped layouts and on hand-made ones with known symmetry groups.
#include "auvdock/geometry/dock_symmetry.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

DockModel Ring(int n, double radius, const std::vector<double>& angles_deg = {}) {
  DockModel dock;
  for (int k = 0; k < n; ++k) {
    const double a = angles_deg.empty() ? 2.0 * kPi * k / n : angles_deg[k] * kPi / 180.0;
    dock.lights.push_back({k, Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), 0.0)});
  }
  return dock;
}

// Every symmetry maps every light onto the light its permutation names, one to one.
void ExpectValid(const DockModel& dock, const std::vector<DockSymmetry>& symmetries) {
  for (const DockSymmetry& s : symmetries) {
    ASSERT_EQ(s.permutation.size(), dock.lights.size());
    EXPECT_NEAR((s.R.transpose() * s.R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
    EXPECT_NEAR(s.R.determinant(), 1.0, 1e-9);
    std::set<int> images(s.permutation.begin(), s.permutation.end());
    EXPECT_EQ(images.size(), dock.lights.size());
    for (size_t i = 0; i < dock.lights.size(); ++i) {
      const Eigen::Vector3d q = s.R * dock.lights[i].p_D + s.t;
      EXPECT_LT((q - dock.lights[s.permutation[i]].p_D).norm(), 1e-6);
    }
  }
}

TEST(DockSymmetry, TDockHasOnlyTheIdentity) {
  const DockModel dock = test::LoadDock("t_shape.yaml");
  const auto s = FindDockSymmetries(dock);
  ASSERT_EQ(s.size(), 1u);  // the mirror about the stem shows the deck's back: left out
  EXPECT_TRUE(s[0].IsIdentity());
  EXPECT_EQ(DescribeDockSymmetries(s), "none");
}

TEST(DockSymmetry, RingWithAlternatingGapsIsFourFold) {
  const DockModel dock = test::LoadDock("ring_8.yaml");
  const auto s = FindDockSymmetries(dock);
  ASSERT_EQ(s.size(), 4u);
  ExpectValid(dock, s);
  std::multiset<long> angles;
  for (const auto& sym : s) angles.insert(std::lround(sym.angle_rad * 180.0 / kPi));
  EXPECT_EQ(angles, (std::multiset<long>{0, 90, 90, 180}));
  for (size_t k = 1; k < s.size(); ++k) EXPECT_NEAR(std::abs(s[k].axis_D.z()), 1.0, 1e-9);
}

TEST(DockSymmetry, EvenlySpacedRingIsEightFold) {
  const DockModel dock = Ring(8, 0.7);
  const auto s = FindDockSymmetries(dock);
  EXPECT_EQ(s.size(), 8u);
  ExpectValid(dock, s);
}

TEST(DockSymmetry, CornersAndRaisedCentreIsTwoFold) {
  const DockModel dock = test::LoadDock("corners_centre_5.yaml");
  const auto s = FindDockSymmetries(dock);
  ASSERT_EQ(s.size(), 2u);
  ExpectValid(dock, s);
  EXPECT_NEAR(s[1].angle_rad, kPi, 1e-9);
  EXPECT_EQ(s[1].permutation, (std::vector<int>{2, 3, 0, 1, 4}));
}

TEST(DockSymmetry, NonPlanarLayoutKeepsHalfTurnsThatFlipIt) {
  // A square with one light above and one below its centre: the half-turns about the square's
  // diagonals and sides swap the two, and every one of them is a symmetry of this 3-D layout.
  DockModel dock = Ring(4, 0.5);
  dock.lights.push_back({4, Eigen::Vector3d(0, 0, -0.3)});
  dock.lights.push_back({5, Eigen::Vector3d(0, 0, 0.3)});
  const auto s = FindDockSymmetries(dock);
  EXPECT_EQ(s.size(), 8u);  // the dihedral group of the square
  ExpectValid(dock, s);
}

TEST(DockSymmetry, ToleranceDecides) {
  DockModel dock = test::LoadDock("ring_8.yaml");
  dock.lights[3].p_D.x() += 0.004;  // 4 mm: still symmetric for a camera
  EXPECT_EQ(FindDockSymmetries(dock, 0.01).size(), 4u);
  dock.lights[3].p_D.x() += 0.05;  // 5 cm: the turns no longer map light 3 onto a light
  EXPECT_EQ(FindDockSymmetries(dock, 0.01).size(), 1u);
}

TEST(DockSymmetry, CollinearLayoutGivesTheIdentity) {
  const DockModel dock = test::LoadDock("centerline_8.yaml");
  EXPECT_EQ(FindDockSymmetries(dock).size(), 1u);
}

// A labelling and each of its symmetric copies have one representative: the copies of a
// partly seen ring are one hypothesis for the matcher, never rivals.
TEST(DockSymmetry, AllCopiesOfALabellingShareOneRepresentative) {
  const DockModel dock = test::LoadDock("ring_8.yaml");
  const auto s = FindDockSymmetries(dock);
  ASSERT_EQ(s.size(), 4u);
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    // 4-6 consecutive lights labelled with distinct detection indices, the rest unseen.
    const int n = static_cast<int>(dock.lights.size());
    const int seen = 4 + trial % 3;
    std::vector<int> detections(n);
    std::iota(detections.begin(), detections.end(), 0);
    std::shuffle(detections.begin(), detections.end(), rng);
    std::vector<int> labelling(n, -1);
    const int first = static_cast<int>(rng() % n);
    for (int k = 0; k < seen; ++k) labelling[(first + k) % n] = detections[k];
    const std::vector<int> representative =
        PermuteLabelling(labelling, s[CanonicalSymmetry(s, labelling)]);
    for (const DockSymmetry& sym : s) {
      const std::vector<int> copy = PermuteLabelling(labelling, sym);
      EXPECT_EQ(PermuteLabelling(copy, s[CanonicalSymmetry(s, copy)]), representative);
      EXPECT_LE(representative, copy);  // the smallest of all copies
    }
  }
}

}  // namespace
}  // namespace auvdock
