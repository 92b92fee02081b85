// Stereo triangulation of a light seen by both cameras of the pair (seed 000, section 3.3.1),
// and the left-right matching of detected lights that precedes it (seed 004: by centroid and
// radius).
//
// Frames: S is the stereo frame = the left camera frame (OpenCV: x right, y down, z forward).
// T_R_L = T_C1_B * T_B_C0 = right.T_B_C^-1 * left.T_B_C maps S into the right camera:
// x_R = R x_S + t. Metres; pixels in the raw (distorted) images.
//
// Linear triangulation (seed 000 eqs. 11-16). With (x', y') the undistorted normalized
// coordinates in a camera whose pose is [R | t] (identity for the left camera), each camera
// gives two rows of the homogeneous system A [X; 1] = 0:
//   (x' r3 - r1) . X = t1 - x' t3,    (y' r3 - r2) . X = t2 - y' t3
// (r_k the rows of R). The 4x3 inhomogeneous system is solved in the least-squares sense
// (QR), which equals the homogeneous SVD solution up to the row weighting.
//
// Covariance (first order): X depends on the 4 pixel coordinates through the undistortion and
// the least-squares solution. For a change ds of one normalized coordinate in row k,
// differentiating A^T (A X - b) = 0 gives
//   dX/ds = -(A^T A)^-1 (r3 e_k + a_k z_c),    e = A X - b, a_k row k, z_c the depth in that camera
// and d(x', y')/d(u, v) = (d(u, v)/d(x', y'))^-1 from the distortion model. Then
//   Sigma_X = J (sigma^2 I_4) J^T,   J = dX/d(u_l, v_l, u_r, v_r).
// The depth (along the viewing ray) is the weak direction: its sigma grows as z^2 / (f b).
//
// Matching (MatchStereoDetections), for every left/right pair of detections:
//   1. epipolar gate: distance of the right point to the epipolar line E x_L of the left point,
//      E = [t]x R, on undistorted normalized coordinates, times the right focal length (pixels);
//   2. the rays meet in front of both cameras (positive disparity) at a depth z_S within
//      [min_depth_m, max_depth_m];
//   3. radius gate: max(r_L, r_R) / min(r_L, r_R) <= max_radius_ratio (the two cameras see a
//      light at nearly the same range, hence nearly the same size).
//   cost = (d_epipolar / epipolar_gate_px)^2 + (ln(r_L / r_R) / ln(max_radius_ratio))^2.
// Then a one-to-one assignment, per connected group of candidates, by exhaustive search: the
// most pairs, then the lowest total cost, subject to the ordering constraint: two pairs whose
// left points lie on a common epipolar line (each could pair with the other's right point)
// must keep their order along that line, measured as the angle phi between the ray and the
// baseline (phi_R > phi_L is the positive disparity). This holds for points on a plane that
// does not pass between the two cameras, like the dock deck, and it disambiguates lights on a
// line parallel to the baseline (which share an epipolar line and a radius). Every assignment
// with as many pairs and a cost within ambiguity_margin of the best is also a plausible answer;
// only the pairs common to all of them are returned, so an ambiguous pair is dropped rather
// than guessed. Groups too large to search exhaustively fall back to accepting only mutual,
// unambiguous best pairs.
//
// Reference: seed 000 (Zhu et al., Control and Decision 2025, eqs. 11-16); Hartley and
// Zisserman, Multiple View Geometry, 2nd ed., sections 9.6 (essential matrix), 12.2 (linear
// triangulation); seed 004 (left-right matching by circle centre and radius).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct TriangulatedPoint {
  bool ok = false;
  std::string reason;                                    // why not ok (empty when ok)
  Eigen::Vector3d p_S = Eigen::Vector3d::Zero();         // in S = the left camera frame, m
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of p_S, m^2
  double reprojection_rms_px = 0.0;  // sqrt((|r_left|^2 + |r_right|^2) / 2), pixels
};

// uv_left / uv_right: raw (distorted) pixels of the same point. pixel_sigma: 1-sigma noise
// per pixel coordinate, for the covariance. ok = false for NaN/Inf input, a non-positive
// pixel_sigma, parallel rays (the parallax angle times the left focal length is below
// max(pixel_sigma, 0.05) pixels: the depth is noise), and a point behind either camera.
TriangulatedPoint TriangulateLinear(const Eigen::Vector2d& uv_left, const Eigen::Vector2d& uv_right,
                                    const CameraCalibration& left, const CameraCalibration& right,
                                    double pixel_sigma);

struct StereoMatchOptions {
  double epipolar_gate_px = 2.0;  // max distance to the epipolar line, right image, pixels
  double min_depth_m = 0.2;       // z_S range of the triangulated light
  double max_depth_m = 30.0;
  double max_radius_ratio = 1.6;   // larger / smaller radius; ignored if a radius is <= 0
  double ambiguity_margin = 0.25;  // in cost units (each gate term is 1 at its limit)
};

// Pairs (left index, right index), sorted by left index, each detection used at most once.
// Detections with NaN/Inf centroids are ignored.
std::vector<std::pair<int, int>> MatchStereoDetections(const std::vector<LightDetection>& left,
                                                       const std::vector<LightDetection>& right,
                                                       const CameraCalibration& left_cal,
                                                       const CameraCalibration& right_cal,
                                                       const StereoMatchOptions& options = {});

}  // namespace auvdock
