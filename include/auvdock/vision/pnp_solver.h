// Monocular pose from known 3-D points and their pixels (Perspective-n-Point): the pose of the
// dock seen by one camera (seed 000, section 3.2, eq. 10).
//
// Problem (eq. 10, in the raw distorted image):
//   (R, t) = argmin 1/2 sum_i |pi(R X_i + t) - u_i|^2
// with X_i the model points (dock frame D, metres), u_i the detected pixels (distorted, OpenCV
// pixel convention) and pi the full pinhole + radial-tangential projection of
// PinholeRadtanCamera. The pose is T_C_D: x_C = R X + t (OpenCV's rvec/tvec convention).
//
// Method:
//   1. Closed-form starts on undistorted normalized coordinates (the distortion is only
//      inverted here):
//      - (nearly) coplanar points: a homography DLT on the points' best-fit plane, decomposed
//        as H ~ [r1 r2 t] (Zhang, PAMI 2000), plus its mirror about the line of sight (the
//        second minimum of a planar target seen nearly fronto-parallel);
//      - non-coplanar points: EPnP (Lepetit, Moreno-Noguer, Fua, IJCV 2009) with the N = 1..3
//        kernel approximations and a Gauss-Newton polish of the betas;
//      - at most 5 points (where both of the above are fragile, e.g. 4 of 5 dock lights on one
//        line leave the homography undetermined): P3P on every triple (Grunert's law-of-cosines
//        system reduced to a quartic), the 3 poses that best reproject all points;
//      - initial_T_C_D, when given (see also step 2b).
//      Points with a thickness between the planar and non-planar regimes get both kinds.
//   2. Levenberg-Marquardt (Marquardt's diagonal damping, Nielsen's damping update) on the
//      whitened pixel residuals through the full distortion model, with the analytic Jacobian
//        d u/d x_C = diag(fx, fy) * d(distort)/d(x, y) * [1/Z 0 -X/Z^2; 0 1/Z -Y/Z^2],
//      (times L_i^-1),
//      over a left perturbation R <- Exp(dtheta) R, t <- t + dt, so that
//        d x_C/d dtheta = -[R X]x,   d x_C/d dt = I.
//      Every start is refined; the lowest final cost among the converged starts with every
//      point in front of the camera wins -- unless step 2b finds a rival. (OpenCV's
//      SOLVEPNP_ITERATIVE refines one start and can stop in a worse local minimum with few or
//      noisy points; where both reach the same minimum they agree to its tolerance, ~1e-7.)
//  2b. Two-fold ambiguity (4 or more points): a planar target has a second local minimum, the
//      plane tilted the other way about the line of sight, which the pixel noise can make as
//      good as the true one or better -- e.g. the T dock's stem (3 collinear lights) plus one
//      bar light seen from 2.5 m nearly straight down: the two minima are 21 deg apart in roll
//      and 0.9 m apart across the dock, their squared errors differ by 0.1 px^2 (default
//      scenario, t = 27.5 s). So the flipped twin of the best minimum is refined as well, and a
//      converged minimum that is distinct (Mahalanobis distance^2 from the best, in the best's
//      covariance, above ambiguity_chi2) and fits about as well (chi-square above the best's
//      by less than ambiguity_chi2, a likelihood ratio below e^(chi2/2)) makes the pose
//      ambiguous. Then initial_T_C_D, if given, chooses: the minimum whose rotation is nearer
//      to it wins if it is at most prediction_angle_ratio times as far as the other (the two
//      differ mainly by the flip rotation, tens of degrees, against a prediction error of about
//      a degree); otherwise -- or without initial_T_C_D -- ok = false, "ambiguous: ...", with
//      both minima in ambiguous_T_C_D. So initial_T_C_D must be a pose known independently of
//      these pixels (a tracked prediction), never one picked among their minima by cost.
//   3. Covariance by first-order propagation at the solution:
//        P_local = s (J^T Sigma^-1 J)^-1                 over (dtheta, dt)
//        P       = G P_local G^T,  G = blockdiag(Jl(rvec)^-1, I)
//      where rvec = Log(R) and Jl is the left Jacobian of SO(3), because
//      Exp(rvec + d rvec) = Exp(Jl(rvec) d rvec) Exp(rvec). P is the covariance of OpenCV's
//      parameters (rvec, tvec); P_local is also returned for the estimator's manifold. Here
//      s = max(1, s0^2) and s0^2 = chi2 / (2n - 6) the a-posteriori variance factor (the
//      minimum's chi-square over its degrees of freedom; 1 when 2n = 6): pixels that fit worse
//      than their covariances claim (a biased or smeared centroid, a poor camera model) widen the
//      covariance by the factor their residuals show; ones that fit better leave it as claimed
//      (four points leave 2 degrees of freedom, too few to shrink it by).
//      inflate_by_variance_factor = false keeps s = 1.
//
// With exactly 3 points P3P has up to 4 exact solutions, so without initial_T_C_D the answer
// is "ambiguous" (ok = false); with it, the solver refines from it (6 residuals, 6 unknowns;
// step 2b does not apply).
//
// Frames and units: X in the model (dock) frame D, metres; pixels in the raw image; the
// rotation vector in radians, translation in metres.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct PnpOptions {
  int max_iterations = 50;   // Levenberg-Marquardt iterations per start
  // 1-sigma pixel noise per coordinate, for the weights and the covariance when no per-pixel
  // covariances are given.
  double pixel_sigma = 0.3;
  // Converged when max_k |J^T r|_k <= gradient_tolerance * max_k |J^T r|_k at the start,
  // or when the step |delta| <= step_tolerance * (|(rvec, t)| + step_tolerance),
  // or when an accepted step lowers the cost by less than function_tolerance * cost.
  double gradient_tolerance = 1e-10;
  double step_tolerance = 1e-12;
  double function_tolerance = 1e-14;
  // Step 2b: a distinct minimum fitting within this chi-square of the best makes the
  // pose ambiguous; <= 0 turns the check off (the lowest cost then always wins).
  double ambiguity_chi2 = 9.0;
  // Step 2b: initial_T_C_D chooses a minimum only if it is at most this fraction of its rotation
  // distance to the other one away from it.
  double prediction_angle_ratio = 0.5;
  // Step 3: widen the covariance by the a-posteriori variance factor when it exceeds 1.
  bool inflate_by_variance_factor = true;
};

struct PnpResult {
  bool ok = false;
  std::string reason;  // why not ok (empty when ok)
  Pose3 T_C_D;         // model (dock) -> camera: x_C = R X + t, OpenCV's convention
  // Covariance of (rvec, t): rvec = Log(R) (OpenCV's Rodrigues vector, |rvec| <= pi, rad),
  // t in metres, in that order.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  // Covariance of the left perturbation (dtheta, dt): R = Exp(dtheta) R_hat, t = t_hat + dt.
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
  double rms_px = 0;   // sqrt(mean_i |pi(x_Ci) - u_i|^2), pixels (unweighted)
  double chi2 = 0;     // sum_i e_i^T Sigma_i^-1 e_i at the solution
  int dof = 0;         // 2n - 6
  double variance_factor = 1.0;  // s0^2 = chi2 / dof (1 when dof = 0); see step 3
  int iterations = 0;  // Levenberg-Marquardt iterations of the winning start
  // Step 2b: when two minima fit the pixels about equally well, both (lowest cost first) --
  // whether initial_T_C_D chose one (ok, T_C_D is one of them) or not (ok = false).
  std::vector<Pose3> ambiguous_T_C_D;
};

// points_D[i] projects to pixels_distorted[i], with covariance pixel_covariances[i] (pixels^2)
// if given (empty: pixel_sigma^2 I for every pixel). See the file comment for the method.
// ok = false with a reason for: fewer than 3 correspondences, size mismatch, NaN/Inf input,
// a pixel covariance that is not symmetric positive definite,
// collinear model points, 3 points without initial_T_C_D (ambiguous), two minima that fit
// equally well and that initial_T_C_D does not tell apart (ambiguous), points behind the camera
// at the solution, singular normal equations (an unobservable pose), no convergence, and a
// non-positive pixel_sigma.
// The covariance of the camera's pose in the dock frame, T_D_C = T_C_D^-1, in the tangent space
// of run's covariance.csv [dp_D (m), dtheta_D (rad)] (T_D_C = (p + dp, Exp(dtheta) q),
// factors/pose_manifold.h), from PnpResult::covariance_local (the left perturbation (dtheta, dt)
// of T_C_D = (R, t), in the camera frame). From T_D_C = (-R^T t, R^T), to first order:
//   dtheta_D = -R^T dtheta,   dp_D = -R^T ([t]x dtheta + dt).
Eigen::Matrix<double, 6, 6> CameraInDockCovariance(
    const Pose3& T_C_D, const Eigen::Matrix<double, 6, 6>& covariance_local);

PnpResult SolvePnp(const std::vector<Eigen::Vector3d>& points_D,
                   const std::vector<Eigen::Vector2d>& pixels_distorted,
                   const PinholeRadtanCamera& camera, const PnpOptions& options = {},
                   const std::optional<Pose3>& initial_T_C_D = std::nullopt,
                   const std::vector<Eigen::Matrix2d>& pixel_covariances = {});

}  // namespace auvdock
