// Light matching by prediction ("tracking"): label the detected guide lights with the dock
// lights they are, given a predicted camera pose (from the estimator, or from a verified
// hypothesis of the RANSAC matcher).
//
// Math. Each dock light L is projected with the prediction, p_L = pi(T_C_D * p_D_L) (pixels,
// with distortion). A pose error of the size the estimator has between frames (centimetres,
// about a degree) moves every projection by nearly the same image offset -- 1 deg is ~8 px for
// the default 640x512, 70 deg camera -- while the pattern itself stays nearly rigid. At long
// range that offset is as large as the spacing of the lights (~14 px at 8 m, 60 deg oblique), so
// nearest-projection gating alone would mislabel neighbours. The matcher therefore:
//   1. searches the common offset o, |o| <= gate_px: candidates are 0 and every detection minus
//      projection within the gate; a candidate's support is the number of lights with a
//      detection within their residual gate r_L of p_L + o; the most supported candidate wins
//      (ties: smaller squared residual), and o is re-estimated as the mean residual of its
//      support;
//   2. assigns by gated Hungarian (SolveAssignment): cost |d_j - (p_L + o)| in pixels,
//      forbidden beyond r_L;
//   3. (refine_pose) refines T_C_D on those matches (RefinePoseOnCorrespondences; each match
//      weighted by its detection's own covariance, use_detection_covariance); while the
//      fit is worse than pixel_noise_px explains (PoseFitConsistentWithNoise) or leaves a match
//      more than final_gate_px away, excludes the match whose removal leaves the most
//      consistent fit (never below 4: a minimal set cannot be checked -> kFailed), and
//      re-associates every light at the refined pose by gated Hungarian with final_gate_px,
//      until the labelling is stable. The wide gates of steps 1-2 only have to absorb the
//      prediction error; the final labels are checked at the noise level, so a spurious
//      detection near a missing light's rough position is not taken for it;
//   4. refuses to guess (kAmbiguous, with the reason)
//      - when another offset with the same support gives a different labelling -- unless the
//        offset nearest the prediction is decisively nearer than every such rival (each farther
//        than decisive_offset_ratio x max(its |o|, min_residual_gate_px)), which then wins: a
//        prediction is more likely off by a little than by a lot, and lights mirrored on a
//        surface below them (reflections, ~3 light radii down) otherwise explain as many lights
//        at an offset of their own;
//      - when a labelling with one light less contradicts the chosen one from an offset
//        decisively nearer the prediction (same ratio): along a row of evenly spaced lights (a
//        T's stem) with one light missed, a spurious detection one spacing beyond the row lets
//        the pattern shifted by one spacing explain one light more than the truth;
//      - when a matched detection has a second light (or a light has a second detection) within
//        its gate no more than ambiguity_margin_px farther than the chosen one -- e.g. two lights
//        projecting onto one detection.
// r_L = clamp(spacing_fraction * (distance from p_L to the nearest other projected light),
//             min_residual_gate_px, residual_fraction_of_gate * gate_px):
// gates of neighbouring lights do not overlap unless lights project within a few pixels of each
// other, and they are wide enough for the remaining shape error of the prediction (a 1 deg error
// about the optical axis moves a point 250 px from the centre by ~4 px).
// Fewer than min_matches matches -> kFailed.
//
// Frames and units: T_C_D maps dock coordinates into the camera frame (OpenCV: x right, y down,
// z optical axis); pixels in the raw (distorted) image, (0, 0) the centre of the top-left pixel.
//
// Context: seed 000 (Zhu et al. 2025) matches without a prediction (see
// omnidirectional_matcher.h); this matcher is the cheap per-frame path once a pose is known, and
// the last step of MatchRansac (ransac_matcher.h).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct TrackingMatcherOptions {
  double gate_px = 20.0;              // largest expected prediction error (offset search radius)
  double spacing_fraction = 0.35;     // residual gate as a fraction of the projected light spacing
  double min_residual_gate_px = 1.5;  // floor of the residual gate (a few noise sigmas)
  // Ceiling of the residual gate as a fraction of gate_px: what is left of a pose error once the
  // common offset is removed is a fraction of that offset.
  double residual_fraction_of_gate = 0.4;
  double ambiguity_margin_px = 1.0;  // a second choice this close to the first is ambiguous
  // Step 4: an equally supported offset with another labelling is no rival when it is this many
  // times as far from the prediction as the nearest one (<= 0: every such offset is a rival).
  double decisive_offset_ratio = 3.0;
  bool refine_pose = true;           // step 3
  double final_gate_px = 2.5;        // step 3: ~5-8 sigma of the centroid noise (0.3-0.5 px)
  double pixel_noise_px = 0.3;       // step 3: 1-sigma centroid noise per axis
                                     // (CameraCalibration::pixel_noise_px)
  double consistency_alpha = 1e-4;   // step 3: false-alarm rate of the outlier exclusion
  double acceptance_alpha = 1e-8;    // step 3: a final fit less likely than this -> kFailed
  int min_matches = 3;
  double min_depth_m = 0.05;  // lights closer to the camera plane than this are not projected
  // Step 3 with each detection's own centroid covariance: a detection whose claimed sigma
  // s_j = sqrt(trace(C_j) / 2) exceeds pixel_noise_px (a light cut by the border, a large
  // saturated core) weighs (pixel_noise_px / s_j)^2 in the refinement and the consistency
  // test, and its final gate is max(final_gate_px, 3 s_j). false: one noise for all.
  bool use_detection_covariance = true;
};

// MatchResult::cost is the RMS residual (px) of the matches after removing the common offset.
MatchResult MatchByPrediction(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera, const Pose3& predicted_T_C_D,
                              const TrackingMatcherOptions& options);

// The same with default options and the given gate (px).
MatchResult MatchByPrediction(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera, const Pose3& predicted_T_C_D,
                              double gate_px);

// Levenberg-Marquardt refinement of T_C_D on correspondences between dock points (D, metres) and
// undistorted normalized image coordinates (PinholeRadtanCamera::Unproject): minimises
//   sum_i |(fx (X_i/Z_i - x_i), fy (Y_i/Z_i - y_i))|^2,  (X, Y, Z) = R_C_D p_D_i + p_C_D,
// the reprojection error in pixel-equivalent units (the local scale change of the distortion, a
// few percent, is ignored). Rotation perturbed on the left, R <- Exp(dtheta) R. Needs >= 3
// correspondences; converges to the local minimum near the start. weights (empty: all 1)
// multiply each correspondence's squared error. Returns the final weighted squared error (px^2).
double RefinePoseOnCorrespondences(const std::vector<Eigen::Vector3d>& points_D,
                                   const std::vector<Eigen::Vector2d>& normalized_xy, double fx,
                                   double fy, Pose3* T_C_D,
                                   const std::vector<double>& weights = {});

// True when a pose fit on num_matches correspondences is consistent with isotropic Gaussian
// pixel noise of sigma_px per axis: P(chi-square with 2 n - 6 degrees of freedom >
// squared_error_px2 / sigma^2) >= alpha (always true for n <= 3).
bool PoseFitConsistentWithNoise(double squared_error_px2, int num_matches, double sigma_px,
                                double alpha = 1e-4);

}  // namespace auvdock
