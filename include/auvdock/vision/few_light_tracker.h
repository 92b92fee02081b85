// A dock's lights followed through frames with too few of them for a pose of their own (the dock
// entering or leaving a camera's view, 1-3 lights among the deck's fittings), from the poses of
// the frames next to them: `detect` walks from each run of posed frames into the frames without a
// pose beside it, forward in time and, on recorded footage, backward (two_way_light_bridge.h).
// A live system has the IMU for this (the window's prediction, prediction_association.h); a
// camera on its own has the motion of its last poses.
//
// State: T_C_D and its change per frame (omega, v), a rate that persists for about tau =
// acceleration_time_s (first-order Gauss-Markov, rho = exp(-dt / tau) per frame):
//   R_{k+1} = Exp(omega_k) R_k,  p_{k+1} = p_k + v_k,  (omega, v)_{k+1} = rho (omega, v)_k + noise.
// What no light observes (the range to a single light under the lens) then stops changing after
// ~tau instead of running on at the last rate.
// (Walking backward in time is the same with the frames in reverse order.) Error state
// x = (dtheta, dp, domega, dv), the pose perturbed on the left as in SolvePnp
// (R <- Exp(dtheta) R, p <- p + dp). A Kalman filter on x:
//   start:   from m >= min_start_poses consecutive posed frames (in walking order, the last one
//            next to the frames to walk): the rate is the least-squares slope of their poses
//            (rotations as Log(R_i R_last^T)) against the frame index, with covariance
//            12 / (m (m^2 - 1)) times their mean PnP covariance; the pose is the last one with its
//            own covariance (the two taken as uncorrelated).
//   predict: pose += rate, rate *= rho; P <- F P F^T + G, F = [[I, I], [0, rho I]],
//            G = diag(0, Q): the rate's change per frame, a white-noise acceleration whose
//            spectral density is the vehicle's largest acceleration squared times
//            acceleration_time_s (how long such an acceleration lasts), over the frame interval
//            dt:
//            sigma_omega = max_angular_acceleration sqrt(tau dt^3), sigma_v = (max_acceleration
//            + max_angular_acceleration |p|) sqrt(tau dt^3) + |omega| |v| (a turn moves the
//            dock's origin in the camera frame by its distance, and turns the rate v). Taken
//            as white at the frame rate instead, the same acceleration would be trusted to
//            average out over a few frames: at 60 frames/s a real camera's walk then lost a LED
//            7 px (4 sigma) from its prediction after a third of a second.
//   gate:    each dock light L projects to u_L with C_L = J_L P_pose J_L^T (J_L:
//            guided_light_search.h's ProjectionPoseJacobian); detection j is within L's gate when
//            (u_j - u_L)^T S^-1 (u_j - u_L) <= gate_chi2, S = C_L + R_j, R_j the detection's own
//            covariance with every eigenvalue at least sigma^2, sigma = max(pixel_noise_px, the
//            start poses' own residual per axis): a camera model that fits the lights to a
//            pixel (a real lens, a hand-measured layout) misses by as much on the walk.
//   label:   j is L when L is the only guiding light whose gate holds j and j the only detection
//            in L's gate (never a guess between two); L guides when its 1-sigma is at most
//            max_sigma_px or guide_spacing_fraction of its distance to the nearest other light's
//            projection (a light that the lights seen do not pin down, e.g. the T's bar while
//            only its stem is in view, guides nothing: it is not labelled, and its linearised
//            gate, which may reach anywhere, competes for no detection, but still counts for the
//            verdict). The
//            spacing term is for lights within a metre or so: there the vehicle's acceleration
//            alone moves a light by 10-20 px a frame, while the nearest other light is hundreds
//            of pixels away.
//   doubtful: a guiding light with no detection in its gate may take a doubtful candidate (one
//            the detector rejected on appearance alone: a light too close to the lens to show
//            its colour, blob_light_detector.h; or a saturated disc wider than any blob,
//            saturated_disc.h) in its gate, with that candidate's covariance:
//            the nearest to the prediction, when every other doubtful candidate in the gate is
//            the same blob at another scale (within its radius) and no other guiding light's
//            gate holds it. Doubtful candidates are never judged (they are rejected already).
//            On the randomised renders the downward camera, landed, sees one light filling the
//            image, whitened: the walk carries it on from the poses before touchdown.
//   update:  Gauss-Newton on the labelled lights (detections and doubtful candidates) with the
//            prediction as prior (an iterated Kalman update); the normalised innovation squared
//            over them must pass chi-square with 2 n degrees of freedom at consistency_alpha, or
//            the walk is lost (a wrong label the gate let through, or motion the rate model
//            cannot follow).
//   verdict: a detection outside every in-view light's gate at unexplained_chi2, farther than
//            unexplained_floor_px from every light and farther than unexplained_spacing_fraction
//            of each light's distance to its nearest neighbour's projection, is no light of the
//            dock at this pose (a fitting or a speck that passed the detector; MonoLightPipeline
//            step 6 does the same with a pose of the frame's own); so is a detection near lights
//            only that this step labelled with another detection or candidate (a second
//            detection of a light, a glint beside it). The spacing term is the
//            camera and dock model's error, which the start poses' residual understates for the
//            lights they did not see: on the real pool clip's poorer model (5-8 px on the
//            labels) a walk put a LED 19 px from its prediction at a residual of 1.3 px. A frame with detections of which none is labelled
//            is not judged: the prediction may have lost the lights (a jerk the rate model
//            cannot follow) rather than every detection being clutter; more than
//            max_unlabelled_frames such frames in a row end the walk.
// The walk ends when the prediction no longer guides (no light in the image guides, or no light
// within image_margin_px of the image), after max_frames, or when lost.
//
// Units: pixels (raw, distorted image), metres, radians; frames: T_C_D maps dock coordinates into
// the camera frame (OpenCV).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct FewLightTrackerOptions {
  int min_start_poses = 3;  // consecutive posed frames that give the rate
  int max_start_poses = 10;
  double max_acceleration_mps2 = 0.3;           // the vehicle's, for the process noise
  double max_angular_acceleration_radps2 = 0.2;
  double acceleration_time_s = 1.0;
  double gate_chi2 = 13.8;          // chi-square 2 dof, p = 0.999
  double unexplained_chi2 = 18.4;   // chi-square 2 dof, p = 0.9999
  double unexplained_floor_px = 4.0;
  double unexplained_spacing_fraction = 0.35;
  double consistency_alpha = 1e-4;
  double pixel_noise_px = 0.3;      // floor of a detection's sigma (CameraCalibration)
  double max_sigma_px = 10.0;       // a prediction this uncertain no longer guides ...
  double guide_spacing_fraction = 0.2;  // ... unless within this fraction of its spacing
  double image_margin_px = -20.0;   // lights this far outside the image are still judged
  int max_frames = 150;
  int max_unlabelled_frames = 2;
};

// One frame walked: the labels and the verdict per detection, and the filtered pose.
struct FewLightStep {
  std::vector<int> light_ids;    // per detection: dock light id or -1
  std::vector<bool> unexplained;  // per detection: no light of the dock at this pose
  std::vector<int> doubtful_light_ids;  // per doubtful candidate: dock light id or -1
  int labelled = 0;  // detections labelled
  Pose3 T_C_D;
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
};

class FewLightTracker {
 public:
  using Matrix6 = Eigen::Matrix<double, 6, 6>;

  // frame_interval_s: the time between two frames (1 / rate_hz). Throws std::invalid_argument
  // for options out of range.
  FewLightTracker(const PinholeRadtanCamera& camera, const DockModel& dock,
                  double frame_interval_s, const FewLightTrackerOptions& options = {});

  // Starts a walk from consecutive posed frames in walking order (the last one next to the
  // first frame to walk), each pose with its PnP covariance (SolvePnp's left perturbation).
  // residual_sigma_px: the start poses' typical residual per axis (0: none known). False (and
  // no walk) with fewer than min_start_poses.
  bool Start(const std::vector<Pose3>& poses, const std::vector<Matrix6>& covariances,
             double residual_sigma_px = 0.0);

  // The next frame in walking order: its detections and, optionally, its doubtful candidates
  // (what the detector rejected on appearance alone, and saturated discs, each with its centroid
  // covariance). Nothing when the walk has ended (why: end_reason()).
  std::optional<FewLightStep> Step(const std::vector<LightDetection>& detections,
                                   const std::vector<LightDetection>& doubtful = {});

  bool walking() const { return walking_; }
  const std::string& end_reason() const { return end_reason_; }

 private:
  using Matrix12 = Eigen::Matrix<double, 12, 12>;
  void End(const std::string& reason);

  PinholeRadtanCamera camera_;
  DockModel dock_;
  double dt_;
  FewLightTrackerOptions options_;
  bool walking_ = false;
  int frames_ = 0;
  int unlabelled_frames_ = 0;
  double noise_px_ = 0.0;
  std::string end_reason_;
  Pose3 T_C_D_;
  Eigen::Vector3d omega_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero();
  Matrix12 P_ = Matrix12::Zero();
};

}  // namespace auvdock
