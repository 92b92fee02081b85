// Light matching without a prediction, robust to missing and spurious lights: hypothesise a
// camera pose from three detections and three dock lights (P3P), verify it against every
// detection, and keep the verified labelling only if no other labelling explains the image
// about as well. The requirement is "never more than 1 % silently wrong": refusing (kAmbiguous,
// kFailed) is cheap, the estimator has other sensors and the next frame.
//
// Math.
//  * Detections are undistorted to normalized coordinates x = (X/Z, Y/Z) and unit bearings f.
//  * P3P (Grunert 1841, in the notation of Haralick et al., "Review and analysis of solutions of
//    the three point perspective pose estimation problem", IJCV 13(3), 1994): with the distances
//    s_i along the bearings and the law of cosines on the sides a = |X2 - X3|, b = |X1 - X3|,
//    c = |X1 - X2|, substituting s2 = u s1, s3 = v s1 and eliminating u leaves a quartic in v
//    (coefficients built here by polynomial products). The quartic is badly conditioned when
//    the three depths are similar (v ~ 1, the usual case at range: four nearly equal roots), so
//    its roots -- and the real parts of nearly real complex pairs -- only seed Newton's method
//    on the three law-of-cosines equations in (s1, s2, s3); converged, distinct, positive
//    solutions give the points in C, and the rigid transform follows from the two triangles.
//  * Hypotheses: detection triples whose triangle is at least min_triangle_height_px high,
//    against every ordered non-collinear light triple. For a planar dock seen from above
//    (camera on the -z side of the deck, every light in front) the projection preserves the
//    orientation of every triangle, so only light triples with the detection triple's
//    orientation are tried (half of them).
//  * Verification: reject poses with a light closer than min_depth_m to the camera plane, the
//    camera not min_camera_height_m above the deck, or the camera seen from the lights' centroid
//    less than min_view_elevation_deg above the deck's plane (an edge-on view puts the lights on
//    one image line, where a cable, a rim or a light's beam puts a line of clutter: on the
//    randomised renders every such pose was clutter, 2-3 deg up, metres off, and on the pool
//    clip's zoomed copies poses 0.3-2 deg up were wrong, where the true views are 58-88 deg;
//    our scenarios' views with 4 lights are at least 29 deg up. 10 deg would drop the wrong
//    5-10 deg poses of the zoomed copies too, but cost the clip's poor second camera model
//    labelled poses: 5 is the default); each light claims its nearest detection
//    within hypothesis_gate_px; score = (inliers, then squared residual). Distances are in
//    normalized coordinates scaled by (fx, fy): pixel-equivalent.
//  * Which triples: a labelling with k >= 4 inlier detections is generated from any of its
//    well-spread triples, so triples are tried in priority order (area times detection scores)
//    until every 4-subset of detections contains a tried one (a covering: ~1/2 of the triples
//    for 6 detections, ~1/3 for 8); with more than max_detection_triples a random subset (rng).
//    The search stops after a triple once a hypothesis explains every detection or every light:
//    a rival explaining as many detections contains that triple and has been tried (with more
//    detections than lights it would need spurious detections at lights - 3 predicted places).
//  * Refinement: the best distinct labellings (up to max_refined_hypotheses, within one inlier
//    of the best) are refined by Levenberg-Marquardt (RefinePoseOnCorrespondences) and
//    re-assigned by gated Hungarian within final_gate_px until stable. If the fit is worse than
//    pixel_noise_px explains (PoseFitConsistentWithNoise, consistency_alpha), the other local
//    minimum of a planar target (the deck tilted the other way about the line of sight) is
//    tried, then the detection whose removal alone explains the misfit is excluded.
//  * Symmetric docks (dock_symmetry.h): a labelling and its images under the dock's symmetries
//    explain the image equally well by construction; they are one hypothesis (the pool keeps
//    one canonical copy), not rivals. The reported copy is chosen by a SymmetryHint; every other
//    copy's pose is listed in symmetric_T_C_D, and `symmetry` says how the choice was made.
//  * Decision:
//      - dock lights collinear -> kAmbiguous (no unique pose; the order along the line reverses);
//      - fewer than min_inliers (default 4) inliers -> kFailed: three lights always fit a P3P
//        pose, a labelling is only verified by a fourth;
//      - another labelling with as many inliers whose squared error exceeds the best's by less
//        than ambiguity_chi2 sigma^2 -> kAmbiguous (likelihood ratio below e^(chi2/2));
//      - inlier lights collinear, or (require_redundant_support) collinear once any one of them
//        is removed -> kAmbiguous: a single off-line detection (a "keystone") then fixes the
//        rotation about the line and its own label, and a spurious detection does so in a few
//        percent of views. With the T dock this refuses every view showing only the stem plus
//        one bar end, or the bar plus one stem light;
//      - a fit less likely than acceptance_alpha -> kFailed;
//      - the final labels come from MatchByPrediction (tracking_matcher.h) at the refined pose
//        with final_gate_px, which also refuses two candidates within ambiguity_margin_px.
//    Measured on the T dock (tests/vision/ransac_matcher_test.cc): all 6 lights visible -> 100 %
//    correct; 4 visible + 2 spurious -> 87 % correct when the 4 are in general position, refused
//    otherwise (11 of the 15 sets of 4 contain 3 collinear lights and are genuinely ambiguous),
//    never more than 0.1 % silently wrong.
//
// Frames and units: T_C_D maps dock coordinates into the camera frame (OpenCV: x right, y down,
// z optical axis); dock frame D has z down and the deck at the lights' (mean) z, so the camera
// centre must have a smaller z_D. Pixels in the raw (distorted) image, metres in D.
//
// Why not cv::solveP3P / cv::solvePnP: measured on this machine, cv::solveP3P costs ~40 us per
// call (cv::Mat set-up; SOLVEPNP_AP3P ~80 us) against ~0.3 us for the solver here, and a frame
// with 4 lights and 2 spurious detections needs ~450 P3P problems: ~18 ms instead of ~0.3 ms,
// over the whole 5 ms frame budget. The Levenberg-Marquardt refinement is shared with the
// tracking matcher and works on the normalized coordinates already computed.
//
// Context: seed 000 (Zhu et al. 2025) matches with a 2-D shape method (omnidirectional_matcher.h)
// that assumes all lights visible and a near top-down view; this matcher handles perspective,
// missing and spurious lights.
#pragma once

#include <array>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct RansacMatcherOptions {
  // Inlier gate of a P3P hypothesis. A minimal-set pose extrapolates the centroid noise to the
  // other lights (~1 px at 8 m for 0.3 px noise), so this is wider than the final gate.
  double hypothesis_gate_px = 4.0;
  // Inlier gate after refinement: ~5-8 sigma of the centroid noise (0.3-0.5 px).
  double final_gate_px = 2.5;
  double min_triangle_height_px = 3.0;  // skip nearly collinear detection triples
  int min_inliers = 4;
  // 1-sigma centroid noise per axis (CameraCalibration::pixel_noise_px).
  double pixel_noise_px = 0.3;
  // A rival labelling with as many inliers whose squared reprojection error exceeds the best's
  // by less than ambiguity_chi2 * sigma^2 explains the image about as well (log-likelihood
  // ratio below ambiguity_chi2 / 2).
  double ambiguity_chi2 = 9.0;
  // Outlier exclusion: while a labelling's fit fails PoseFitConsistentWithNoise at this
  // false-alarm rate, the detection whose removal alone explains the misfit is excluded.
  double consistency_alpha = 1e-4;
  // A labelling (best or rival) whose fit is less likely than this is no explanation at all.
  double acceptance_alpha = 1e-8;
  // Refuse labellings whose lights become collinear when any one of them is removed (see the
  // decision rules above). false: refuse them only while some detection is unexplained (which
  // could have played the keystone); measured on the T dock: 5 of 6 lights visible -> 99 %
  // instead of 65 % labelled, but the collinear stem plus one spurious detection -> 2 %
  // silently wrong instead of 0 %.
  bool require_redundant_support = true;
  double ambiguity_margin_px = 0.75;  // final assignment: second choice this close is ambiguous
  double min_camera_height_m = 0.05;  // camera centre at least this far above the deck
  double min_view_elevation_deg = 5.0;  // and at least this far above the deck's plane (0: off)
  double min_depth_m = 0.05;          // every light at least this far in front of the camera
  int max_refined_hypotheses = 4;
  int max_detection_triples = 400;  // beyond this, a random subset of detection triples
  // Lights within this of a symmetric layout make the dock symmetric (dock_symmetry.h).
  double symmetry_tolerance_m = 0.01;
};

// What is known besides the pixels, to choose among a symmetric dock's equally good poses
// (T_C_D S^-1 for every symmetry S): in this order, the copy nearest in rotation to a predicted
// pose (tracking), the copy whose gravity direction R_C_D g_D is nearest to the measured one
// (gravity_C: from the IMU's attitude, any length), the copy that puts a point of the vehicle
// nearest to its position fix (fix_p_D, an acoustic USBL fix of the transponder at p_C = the
// translation of T_C_S, within fix_gate_sigmas fix_sigma_m + fix_range_fraction x the camera's
// distance from the dock of it -- the fix's error and the pose's own, which grows with range: a
// fix that fits no copy is an outlier and tells nothing), the copy whose camera centre's bearing about
// the symmetry axis is nearest to that of the approach direction (approach_direction_D, D frame:
// where the vehicle comes from, seen from the dock). A hint decides only when
// the next copy is at least twice as far from it as the best; otherwise the next hint is asked,
// and with none the first copy is reported as "unresolved", all of them listed.
struct SymmetryHint {
  std::optional<Pose3> predicted_T_C_D;
  std::optional<Eigen::Vector3d> gravity_C;
  std::optional<Eigen::Vector3d> fix_p_D;
  double fix_sigma_m = 0.0;   // 1 sigma per axis, the fix's age included (m)
  double fix_gate_sigmas = 4.0;
  double fix_range_fraction = 0.05;
  Pose3 T_C_S;                // the fixed point's frame in the camera frame
  std::optional<Eigen::Vector3d> approach_direction_D;
};

// A MatchResult plus the pose it was verified with (extends MatchResult, so it can be passed
// wherever a MatchResult is expected).
struct RansacMatchResult : MatchResult {
  std::optional<Pose3> T_C_D;  // set only when status == kOk: refined on the matches
  int num_inliers = 0;         // of the best hypothesis (also when not kOk)
  int num_triples = 0;         // detection triples tried (cost figure)
  int num_p3p = 0;             // P3P problems solved (cost figure)
  int num_poses = 0;           // poses verified
  // A symmetric dock (dock_symmetry.h): the other poses that explain the image exactly as well
  // (T_C_D composed with each non-identity symmetry), and how the reported one was chosen.
  std::vector<Pose3> symmetric_T_C_D;
  std::string symmetry;
  bool symmetry_unresolved = false;  // no hint told the copies apart: the pose is one of them
  bool symmetry_by_prediction = false;  // the prediction (the track) chose the copy
};

RansacMatchResult MatchRansac(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera,
                              const RansacMatcherOptions& options, std::mt19937_64& rng);
RansacMatchResult MatchRansac(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera,
                              const RansacMatcherOptions& options, std::mt19937_64& rng,
                              const SymmetryHint& hint);

// The matcher's test of where a camera may be, for a pose found some other way (tracking, PnP's
// refinement): the camera of T_C_D at least min_camera_height_m above the deck's plane (the
// lights' mean z_D, z down) and seen from the lights' centroid at least min_view_elevation_deg
// above it. A pose that fails it is edge-on to the dock or under it.
bool CameraAboveTheDeck(const DockModel& dock, const Pose3& T_C_D,
                        const RansacMatcherOptions& options);

// The minimal solver on its own: poses T_C_D (up to four) with bearing i (unit, camera frame)
// pointing at point i (dock frame), all three in front of the camera.
std::vector<Pose3> SolveP3P(const std::array<Eigen::Vector3d, 3>& bearings_C,
                            const std::array<Eigen::Vector3d, 3>& points_D);

}  // namespace auvdock
