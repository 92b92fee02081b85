// The symmetries of a dock's light layout: the proper rigid motions S (x -> R x + t, det R = +1)
// that map the set of lights onto itself, light i onto light permutation[i]. A camera cannot
// tell a pose T_C_D from T_C_D S^-1 by the lights alone: the lights then project onto the same
// pixels with their labels permuted (light i of one pose is where light permutation[i] is in
// the other). Examples: a ring of 8 lights at alternating 40/50 degree gaps (4-fold: rotations
// by multiples of 90 degrees about the ring's axis), four corners of a rectangle and a raised
// centre light (2-fold, 180 degrees about the centre's axis), the T dock (none but the
// identity).
//
// Method: every symmetry fixes the lights' centroid c, so t = c - R c. With a the light
// farthest from c and b the light that makes the best-conditioned frame with it (largest
// |(p_a - c) x (p_b - c)|), every candidate image (i, j) of (a, b) with matching distances to c
// and to each other gives R = F(i, j) F(a, b)^T, F the orthonormal frame of (p - c, q - c, their
// cross product); S is kept when it maps every light within tolerance_m of some light, one to
// one. The identity is always first. For a planar layout the half-turns about axes in its plane
// are left out: they map the lights onto themselves but show the camera their back, and lights
// are seen from one side (the matcher keeps the camera on the lights' side). Collinear layouts (no frame) return the identity alone:
// they are degenerate in another way (dock_model.h LightsCollinear).
//
// Units: metres. The tolerance is an absolute distance: lights placed within ~1 cm of a
// symmetric layout are symmetric for a camera metres away, whose pixel noise is ~1 cm there.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/dock_model.h"

namespace auvdock {

struct DockSymmetry {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  std::vector<int> permutation;  // light index (DockModel::lights order) -> light index
  double angle_rad = 0.0;        // rotation angle of R
  Eigen::Vector3d axis_D = Eigen::Vector3d::UnitZ();  // unit rotation axis (any, for identity)
  bool IsIdentity() const { return angle_rad < 1e-9; }
};

std::vector<DockSymmetry> FindDockSymmetries(const DockModel& dock, double tolerance_m = 0.01);

// A labelling (per light, in DockModel::lights order: the index of its detection, or -1) seen
// through symmetry s: light i's detection becomes light permutation[i]'s. The labelling and its
// copies explain the same pixels with poses T and T S^-1.
std::vector<int> PermuteLabelling(const std::vector<int>& detection_of_light,
                                  const DockSymmetry& s);

// The index k of the symmetry whose copy of the labelling is the lexicographically smallest:
// one representative for all copies, so that copies count as one labelling, not as rivals.
// Every copy is made from the labelling itself: applying the symmetries one after another to the
// smallest so far visits products of them and can miss a copy (a 4-fold ring's copies a
// half-turn apart then had different representatives).
size_t CanonicalSymmetry(const std::vector<DockSymmetry>& symmetries,
                         const std::vector<int>& detection_of_light);

// "4-fold about (0, 0, 1)" style summary of the non-identity symmetries; "none" without any.
std::string DescribeDockSymmetries(const std::vector<DockSymmetry>& symmetries);

}  // namespace auvdock
