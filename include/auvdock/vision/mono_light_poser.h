// One camera's identification and pose, frame after frame, without an IMU: the path of
// `auvdock detect` on a user's own footage.
//
// Per frame: with a pose from the previous frame (at most max_gap_frames old), the detections
// are labelled by prediction (MatchByPrediction, tracking_gate_px: the motion between frames);
// otherwise, or if that fails, from scratch (MatchRansac). Tracking needs min_tracked_lights, from
// scratch min_lights. A tracked labelling that leaves recheck_unexplained_detections or more
// detections unexplained is identified from scratch as well, and replaced when that explains as
// many more. The labelled lights then give the pose
// by PnP (SolvePnp, started at the matcher's pose) with the pixel noise
//   sigma = max(camera pixel_noise_px, sqrt(mean over the used detections of trace(C_i) / 2)),
// C_i a detection's own centroid covariance (zero: not measured), so that PnP's covariance and
// the matcher's consistency tests follow the detector's stated accuracy. A PnP fit worse than
// that noise explains inflates the covariance by the a-posteriori variance factor
// s0^2 = (sum of squared residuals) / (sigma^2 (2 n - 6)) when s0^2 > 1. The refined pose,
// tracked or not, must see the deck as the matcher's hypotheses must (CameraAboveTheDeck with
// ransac's limits): a labelling carried by tracking is otherwise never tested there.
//
// A symmetric dock's rival poses (dock_symmetry.h) are told apart by the last pose (the symmetry
// copy nearest to it in rotation), else by gravity_C when given, else reported unresolved with
// every rival pose; identities then stay consistent from frame to frame through tracking.
//
// Every frame without a pose says why (reason). Units: pixels, metres; T_C_D maps dock
// coordinates into the camera frame (OpenCV).
#pragma once

#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"
#include "auvdock/vision/ransac_matcher.h"
#include "auvdock/vision/tracking_matcher.h"

namespace auvdock {

struct MonoLightPoserOptions {
  RansacMatcherOptions ransac;
  TrackingMatcherOptions tracking;
  double tracking_gate_px = 40.0;
  int max_gap_frames = 3;
  int min_lights = 4;
  // While tracking, fewer lights may do (a close dock leaving the image: PnP refines the tracked
  // pose, which tells P3P's solutions apart), but 3 lights fit any pose exactly: nothing checks
  // the labels. On the pool clip, 3 let the labelling drift to a wrong one (precision 0.977 ->
  // 0.940), so by default tracking needs min_lights too.
  int min_tracked_lights = 4;
  bool use_tracking = true;
  // A tracked labelling that leaves this many detections or more unexplained is checked by
  // identification from scratch, which replaces it when it explains this many more (0: never).
  // Tracking can carry a wrong labelling of one light and a few fittings for tens of frames
  // while the true lights stay unexplained beside it (randomised renders, seed 4, cam2).
  int recheck_unexplained_detections = 2;
  // Gravity's direction in the camera frame when the camera's attitude is roughly known (a
  // camera held upright: (0, 1, 0)), to choose among a symmetric dock's poses (SymmetryHint).
  std::optional<Eigen::Vector3d> gravity_C;
  double max_gravity_error_deg = 30.0;  // the hint counts when the chosen copy is this close
  uint64_t seed = 1;
};

struct MonoPoseResult {
  std::vector<int> light_ids;  // per detection: dock light id or -1
  MatchStatus status = MatchStatus::kFailed;
  bool tracked = false;
  std::optional<Pose3> T_C_D;
  // Covariance of the left perturbation of T_C_D (dtheta, dt), the camera frame (SolvePnp),
  // from each light's own centroid covariance, widened by variance_factor when it exceeds 1.
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
  double variance_factor = 1.0;  // the pose's a-posteriori variance factor (SolvePnp)
  double rms_px = 0.0;
  double pixel_sigma_px = 0.0;  // the noise of the identification's gates (median detection's)
  int num_lights = 0;           // used in the pose
  std::string reason;           // why there is no pose (empty with a pose)
  std::vector<Pose3> symmetric_T_C_D;  // rival poses of a symmetric dock (symmetry_note)
  std::string symmetry_note;
};

class MonoLightPoser {
 public:
  MonoLightPoser(const CameraCalibration& camera, const DockModel& dock,
                 const MonoLightPoserOptions& options = {});

  // The next frame's detections.
  MonoPoseResult Process(const std::vector<LightDetection>& detections);
  // The next frame's detections, identified by tracking only (no identification from scratch):
  // for detections that include guesses, which only tracking may label. No pose: the state is
  // as before the frame, and Retry may follow.
  MonoPoseResult ProcessTrackedOnly(const std::vector<LightDetection>& detections);
  // The same frame again with other detections (a second detection pass), when the frame gave no
  // pose: the tracking state is that of the frame, not one frame older. A pose that `accept`
  // (when given) refuses is no pose, and leaves the tracking state as it was (a weak pass's
  // pose that explains too little of the dock must not be tracked from).
  MonoPoseResult Retry(const std::vector<LightDetection>& detections,
                       const std::function<bool(const MonoPoseResult&)>& accept = {});

  // The last pose, while tracking may use it for the next frame (use_tracking, at most
  // max_gap_frames old); otherwise nothing.
  std::optional<Pose3> TrackedPose() const;

 private:
  CameraCalibration camera_;
  DockModel dock_;
  MonoLightPoserOptions options_;
  MonoPoseResult Solve(const std::vector<LightDetection>& detections, bool from_scratch);

  std::mt19937_64 rng_;
  std::optional<Pose3> last_T_C_D_;
  int frames_since_pose_ = 0;
};

}  // namespace auvdock
