#include "auvdock/vision/mono_light_poser.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "auvdock/vision/pnp_solver.h"

namespace auvdock {

MonoLightPoser::MonoLightPoser(const CameraCalibration& camera, const DockModel& dock,
                               const MonoLightPoserOptions& options)
    : camera_(camera), dock_(dock), options_(options), rng_(options.seed) {}

MonoPoseResult MonoLightPoser::Process(const std::vector<LightDetection>& detections) {
  ++frames_since_pose_;
  return Solve(detections, /*from_scratch=*/true);
}

MonoPoseResult MonoLightPoser::ProcessTrackedOnly(const std::vector<LightDetection>& detections) {
  ++frames_since_pose_;
  return Solve(detections, /*from_scratch=*/false);
}

MonoPoseResult MonoLightPoser::Retry(const std::vector<LightDetection>& detections,
                                     const std::function<bool(const MonoPoseResult&)>& accept) {
  const std::optional<Pose3> last_T_C_D = last_T_C_D_;
  const int frames_since_pose = frames_since_pose_;
  MonoPoseResult result = Solve(detections, /*from_scratch=*/true);
  if (result.T_C_D && accept && !accept(result)) {
    last_T_C_D_ = last_T_C_D;
    frames_since_pose_ = frames_since_pose;
    MonoPoseResult refused;
    refused.light_ids.assign(detections.size(), -1);
    refused.pixel_sigma_px = result.pixel_sigma_px;
    refused.reason = "a pose of " + std::to_string(result.num_lights) +
                     " lights, refused (too little of the dock, or the deck seen edge-on)";
    return refused;
  }
  return result;
}

std::optional<Pose3> MonoLightPoser::TrackedPose() const {
  // Called between frames: the next Process counts one more frame since the pose.
  if (!options_.use_tracking || !last_T_C_D_ || frames_since_pose_ + 1 > options_.max_gap_frames) {
    return std::nullopt;
  }
  return last_T_C_D_;
}

MonoPoseResult MonoLightPoser::Solve(const std::vector<LightDetection>& detections,
                                     bool from_scratch) {
  MonoPoseResult result;
  result.light_ids.assign(detections.size(), -1);

  // The noise the detections claim (their own covariances), never below the camera's: the
  // median detection's, so that one detection with a wide covariance (a light cut by the border,
  // a blob in a glow) does not widen every gate of the frame.
  const double sigma = TypicalPixelSigma(detections, camera_.pixel_noise_px);
  result.pixel_sigma_px = sigma;

  const bool can_track =
      options_.use_tracking && last_T_C_D_ && frames_since_pose_ <= options_.max_gap_frames;
  const int needed = can_track ? std::min(options_.min_tracked_lights, options_.min_lights)
                               : options_.min_lights;
  if (static_cast<int>(detections.size()) < needed) {
    result.reason = "only " + std::to_string(detections.size()) + " detections (need " +
                    std::to_string(needed) + ")";
    return result;
  }

  MatchResult match;
  std::optional<Pose3> start;
  if (can_track) {
    TrackingMatcherOptions tracking = options_.tracking;
    tracking.gate_px = options_.tracking_gate_px;
    tracking.pixel_noise_px = sigma;
    tracking.final_gate_px = std::max(tracking.final_gate_px, 6.0 * sigma);
    tracking.min_matches = needed;
    match = MatchByPrediction(detections, dock_, camera_.intrinsics, *last_T_C_D_, tracking);
    if (match.status == MatchStatus::kOk) {
      result.tracked = true;
      start = last_T_C_D_;
    }
  }
  if (!result.tracked && !from_scratch) {
    result.reason = can_track ? "tracking: " + match.reason : "nothing to track";
    return result;
  }
  if (!result.tracked && static_cast<int>(detections.size()) < options_.min_lights) {
    result.reason = "only " + std::to_string(detections.size()) + " detections (need " +
                    std::to_string(options_.min_lights) + " without tracking: " + match.reason +
                    ")";
    return result;
  }
  const auto from_scratch_match = [&]() {
    RansacMatcherOptions ransac = options_.ransac;
    ransac.pixel_noise_px = sigma;
    ransac.final_gate_px = std::max(ransac.final_gate_px, 6.0 * sigma);
    ransac.hypothesis_gate_px = std::max(ransac.hypothesis_gate_px, 10.0 * sigma);
    ransac.min_inliers = options_.min_lights;
    SymmetryHint hint;
    if (last_T_C_D_) hint.predicted_T_C_D = last_T_C_D_;
    hint.gravity_C = options_.gravity_C;
    return MatchRansac(detections, dock_, camera_.intrinsics, ransac, rng_, hint);
  };
  if (!result.tracked) {
    const RansacMatchResult r = from_scratch_match();
    match = r;
    start = r.T_C_D;
    result.symmetric_T_C_D = r.symmetric_T_C_D;
    result.symmetry_note = r.symmetry;
  } else if (from_scratch && options_.recheck_unexplained_detections > 0 &&
             static_cast<int>(detections.size()) >= options_.min_lights &&
             detections.size() >= match.matches.size() +
                                      static_cast<size_t>(options_.recheck_unexplained_detections)) {
    // Tracking can carry a wrong labelling (a few lights and clutter that fit it) while the true
    // lights stay unexplained beside it; identification from scratch that explains decisively
    // more of the frame replaces it.
    const RansacMatchResult r = from_scratch_match();
    if (r.status == MatchStatus::kOk &&
        r.matches.size() >=
            match.matches.size() + static_cast<size_t>(options_.recheck_unexplained_detections)) {
      match = r;
      start = r.T_C_D;
      result.tracked = false;
      result.symmetric_T_C_D = r.symmetric_T_C_D;
      result.symmetry_note = r.symmetry;
    }
  }
  result.status = match.status;
  if (match.status != MatchStatus::kOk) {
    result.reason = std::string(MatchStatusName(match.status)) + ": " + match.reason;
    return result;
  }

  // The pose weighs every light alike, except one whose detection claims far more than the
  // frame's typical sigma (a light cut by the border counts for less: PixelCovarianceForPose);
  // its covariance grows by the a-posteriori variance factor when the lights fit worse than
  // they claim (SolvePnp step 3).
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Matrix2d> covariances;
  std::vector<int> ids(detections.size(), -1);
  for (const LightMatch& m : match.matches) {
    const DockLight* light = dock_.FindLight(m.light_id);
    if (!light || m.detection < 0 || m.detection >= static_cast<int>(detections.size())) continue;
    ids[m.detection] = m.light_id;
    points.push_back(light->p_D);
    pixels.push_back(detections[m.detection].uv);
    covariances.push_back(
        PixelCovarianceForPose(detections[m.detection], sigma));
  }
  PnpOptions pnp;
  pnp.pixel_sigma = sigma;
  const PnpResult pose = SolvePnp(points, pixels, camera_.intrinsics, pnp, start, covariances);
  if (!pose.ok) {
    result.status = MatchStatus::kFailed;
    result.reason = "pnp: " + pose.reason;
    return result;
  }
  // Tracking and PnP's refinement never tested where the camera is: a labelling carried from
  // frame to frame can drift to a pose edge-on to the deck or under it (clutter along a cable
  // fits a layout seen edge-on), which no camera over a dock on the seabed sees.
  if (!CameraAboveTheDeck(dock_, pose.T_C_D, options_.ransac)) {
    result.status = MatchStatus::kFailed;
    result.reason = std::string(result.tracked ? "tracking" : "pnp") +
                    ": the camera would be edge-on to the deck or under it";
    return result;
  }
  result.light_ids = ids;
  result.T_C_D = pose.T_C_D;
  result.rms_px = pose.rms_px;
  result.num_lights = static_cast<int>(points.size());
  result.covariance_local = pose.covariance_local;
  result.variance_factor = pose.variance_factor;
  last_T_C_D_ = pose.T_C_D;
  frames_since_pose_ = 0;
  return result;
}

}  // namespace auvdock
