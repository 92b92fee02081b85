// Seed 000's "omnidirectional" light matching (Zhu et al., "Light visual guidance algorithm for
// AUV situated recovery based on monocular and binocular fusion", Control and Decision 40(1),
// 2025, section 2.2, eqs. 5-9): match the detected guide lights to the dock's design drawing by
// 2-D shape alone, without a pose prediction.
//
// Math (paper, with the additions it leaves implicit; superscript o = design, m = image):
//   eqs. 5-6  centroid-relative vectors p_i = q_i - q_c for the design points (x, y of the lights
//             in D) and for the detections (raw pixels);
//   (added)   both sets are divided by their RMS length: the image is at an unknown scale
//             (range, focal length);
//   eq. 7     the image vectors are rotated by the angle theta of their minimum-area enclosing
//             rectangle. (added) The design is rotated by the angle of ITS rectangle too: the
//             paper's design drawing is implicitly drawn rectangle-aligned, a DockModel need not
//             be. Both sets then live in their own rectangle frames;
//   (added)   a rectangle's angle is only defined modulo 90 deg (which side is "width" is
//             arbitrary), so the image set is tried at the four rotations k * 90 deg, k = 0..3;
//             this subsumes the paper's second matching after a 180 deg flip;
//   (added)   the minimum-area rectangle need not be unique, and is not for the default T: its
//             convex hull is a triangle, and the rectangles flush with each of the triangle's
//             three sides all have twice its area. cv::minAreaRect returns one of them, decided
//             by rounding and perspective, and the method then fails even on top-down views
//             (measured: 12-15 % correct at +-5..15 deg of tilt). So every rectangle flush with
//             a hull edge within rectangle_area_tolerance of the minimum area is a candidate,
//             for the design and for the image, and every pairing is tried (only distinct
//             relative rotations);
//   eqs. 8-9  cost D_ij = |p_i^o - p_j^m'|, Hungarian assignment (SolveAssignment) per
//             rotation, keep the rotation with the lowest mean cost.
// Decisions (added; the paper always answers):
//   - detection count != light count, or fewer than 3 lights -> kFailed;
//   - the design maps onto itself under a rotation (seed 001's centre-line row under 180 deg, a
//     square under 90 deg) -> kAmbiguous for every image;
//   - best and second-best rotations (with different labels) within ambiguity_margin of mean
//     cost -> kAmbiguous;
//   - best mean cost above max_mean_cost -> kFailed (the image does not look like the design).
// Mirror images never arise: image (u right, v down) and D (x, y, with z down) are both
// right-handed about the viewing direction when the camera looks down at the deck.
//
// Assumptions (the paper's setting): a roughly top-down, low-perspective view (the design and the
// image must be similar up to rotation and scale), all lights detected, no spurious detections.
// Strong perspective breaks it. Measured on the default dock and camera (all 6 lights, 0.3 px,
// 2-8 m, tests/vision/omnidirectional_matcher_test.cc): 100 % correct with the camera's roll and
// pitch within +-30 deg of straight down, 98.7 % within +-45 deg, 84.9 % (2.5 % silently wrong)
// within +-60 deg. Use MatchRansac (ransac_matcher.h) there.
//
// Units: pixels in, normalized (unit-RMS) units for the costs; MatchResult::cost is the best
// mean cost in those units.
#pragma once

#include <vector>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct OmnidirectionalMatcherOptions {
  double ambiguity_margin = 0.05;    // normalized units
  double max_mean_cost = 0.3;        // normalized units
  double symmetry_tolerance = 0.05;  // design self-match below this: rotationally symmetric
  // Rectangles flush with a hull edge within this fraction of the minimum area are candidates.
  double rectangle_area_tolerance = 0.1;
};

MatchResult MatchOmnidirectional(const std::vector<LightDetection>& detections,
                                 const DockModel& dock,
                                 const OmnidirectionalMatcherOptions& options = {});

}  // namespace auvdock
