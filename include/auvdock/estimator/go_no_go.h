// The docking go/no-go decision, per estimator output: GO only when the estimate is both precise
// enough for the landing and healthy; otherwise NO-GO with the first reason that failed.
//
// Checks, in order (thresholds in GoNoGoOptions):
//   1. an estimate exists and its covariance is available (a rank-deficient or failed
//      covariance is NO-GO: the estimator cannot say how wrong it is);
//   1b. a pose that the lights fix only up to a symmetric dock's symmetry, with nothing that
//      told the rival poses apart (EstimatorOutput::symmetry_unresolved): the covariance
//      describes one of the rivals, which may be turned by the symmetry from the true pose;
//   2. recent vision: the newest frame with a used vision residual is at most
//      max_vision_age_s old (on the IMU alone the error grows without a bound the vehicle
//      should trust, whatever the covariance says). With the DVL fused the horizontal error
//      is bounded instead (a random walk of the DVL's noise, not the IMU's quadratic drift),
//      and its covariance is honest (mean NEES 4.1 in the stage without lights, README): so
//      while a DVL sample was used at most max_dvl_age_s ago, vision up to
//      max_aided_vision_age_s old is enough, and checks 4-5 decide from the covariance. The cap
//      keeps a long unlit stretch NO-GO whatever the covariance says: nothing but the DVL then
//      stands between the vehicle and an unmodelled DVL bias;
//   3. gating health: over the last gating_window_frames frames, the share of vision residuals
//      rejected by the chi-square gate is at most max_gating_rate (many rejections mean the
//      model and the data disagree: misidentified lights, reflections, a bad calibration);
//   3b. depth health: over the same frames, the share of depth samples rejected by the depth gate
//      is at most max_depth_gating_rate (when at least min_depth_samples came): a depth sensor
//      that the gate keeps rejecting disagrees with the estimate, whichever of the two is wrong
//      (a sensor whose zero is not the dock survey's, taken at its word, made 3 unsafe GO on the
//      default scenario with 0.3 m of offset; EstimatorOptions::estimate_depth_offset);
//   4. lateral precision: 3 sigma of the horizontal position, along the major axis of its 2 x 2
//      covariance in the dock frame (x, y), is at most allowed_lateral_error_m (the landing
//      tolerance of the platform; the major axis covers the along-track and cross-track
//      directions alike);
//   5. heading precision: 3 sigma of the rotation about the dock's z axis at most
//      max_yaw_3sigma_rad.
// Units: metres, radians, seconds. The covariance is the estimator's, in the PoseManifold
// tangent space [dp_D, dtheta_D].
#pragma once

#include <deque>
#include <string>

#include "auvdock/estimator/sliding_window_estimator.h"

namespace auvdock {

struct GoNoGoOptions {
  double allowed_lateral_error_m = 0.10;
  double max_yaw_3sigma_rad = 0.05;  // about 3 degrees
  double max_vision_age_s = 0.5;
  double max_dvl_age_s = 1.0;            // a DVL sample used this recently ...
  double max_aided_vision_age_s = 10.0;  // ... lets vision be this old
  double max_gating_rate = 0.3;
  int gating_window_frames = 20;
  double max_depth_gating_rate = 0.3;
  int min_depth_samples = 5;
};

struct GoNoGoDecision {
  bool go = false;
  std::string reason;  // one line, no commas (it is a CSV field)
};

class GoNoGo {
 public:
  // Throws std::invalid_argument for non-positive thresholds.
  explicit GoNoGo(const GoNoGoOptions& options = {});

  // Decides for one output (and remembers its gating counts for the health check).
  GoNoGoDecision Decide(const EstimatorOutput& output);
  // A frame without an estimate (not initialised, reset): always NO-GO with the given reason.
  GoNoGoDecision NoEstimate(const std::string& reason);

 private:
  GoNoGoOptions options_;
  std::deque<std::pair<int, int>> recent_;  // (used, gated) per frame
  std::deque<std::pair<int, int>> recent_depth_;  // (samples, gated) per frame
};

}  // namespace auvdock
