#include "auvdock/estimator/go_no_go.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace auvdock {
namespace {

std::string Format(const char* format, double a, double b) {
  char buffer[160];
  std::snprintf(buffer, sizeof(buffer), format, a, b);
  return buffer;
}

}  // namespace

GoNoGo::GoNoGo(const GoNoGoOptions& options) : options_(options) {
  if (!(options_.allowed_lateral_error_m > 0.0) || !(options_.max_yaw_3sigma_rad > 0.0) ||
      !(options_.max_vision_age_s > 0.0) || !(options_.max_dvl_age_s > 0.0) ||
      !(options_.max_aided_vision_age_s > 0.0) || !(options_.max_gating_rate >= 0.0) ||
      options_.gating_window_frames < 1 || !(options_.max_depth_gating_rate >= 0.0) ||
      options_.min_depth_samples < 1) {
    throw std::invalid_argument("GoNoGoOptions: thresholds must be positive");
  }
}

GoNoGoDecision GoNoGo::NoEstimate(const std::string& reason) {
  recent_.clear();
  recent_depth_.clear();
  return {false, "no estimate: " + reason};
}

GoNoGoDecision GoNoGo::Decide(const EstimatorOutput& output) {
  recent_.emplace_back(output.n_mono + output.n_stereo, output.n_gated);
  while (static_cast<int>(recent_.size()) > options_.gating_window_frames) recent_.pop_front();
  recent_depth_.emplace_back(output.n_depth, output.n_depth_gated);
  while (static_cast<int>(recent_depth_.size()) > options_.gating_window_frames) {
    recent_depth_.pop_front();
  }

  if (!output.covariance_ok || !output.covariance.allFinite()) {
    return {false, "covariance unavailable (rank-deficient or not computed)"};
  }
  if (output.symmetry_unresolved) {
    return {false, "pose known only up to the dock's symmetry (nothing told its rival poses "
                   "apart: give dock.yaml approach_direction_D or acoustic fixes)"};
  }
  if (output.seconds_since_vision < 0.0) return {false, "no vision yet"};
  const bool dvl_aided =
      output.seconds_since_dvl >= 0.0 && output.seconds_since_dvl <= options_.max_dvl_age_s;
  if (output.seconds_since_vision > options_.max_vision_age_s && !dvl_aided) {
    return {false, Format("no vision for %.2f s (limit %.2f s without the DVL)",
                          output.seconds_since_vision, options_.max_vision_age_s)};
  }
  if (output.seconds_since_vision > options_.max_aided_vision_age_s) {
    return {false, Format("no vision for %.2f s (limit %.2f s with the DVL)",
                          output.seconds_since_vision, options_.max_aided_vision_age_s)};
  }
  int used = 0, gated = 0;
  for (const auto& [u, g] : recent_) {
    used += u;
    gated += g;
  }
  const double rate = used + gated > 0 ? static_cast<double>(gated) / (used + gated) : 0.0;
  if (rate > options_.max_gating_rate) {
    return {false, Format("gating rate %.2f over the recent frames (limit %.2f)", rate,
                          options_.max_gating_rate)};
  }
  int depth_samples = 0, depth_gated = 0;
  for (const auto& [n, g] : recent_depth_) {
    depth_samples += n;
    depth_gated += g;
  }
  if (depth_samples >= options_.min_depth_samples &&
      depth_gated > options_.max_depth_gating_rate * depth_samples) {
    char reason[128];
    std::snprintf(reason, sizeof(reason),
                  "the depth disagrees: %d of %d samples gated over the recent frames (limit %.2f)",
                  depth_gated, depth_samples, options_.max_depth_gating_rate);
    return {false, reason};
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> horizontal(
      output.covariance.topLeftCorner<2, 2>());
  const double lateral_3sigma = 3.0 * std::sqrt(std::max(0.0, horizontal.eigenvalues().maxCoeff()));
  if (lateral_3sigma > options_.allowed_lateral_error_m) {
    return {false, Format("3-sigma lateral %.3f m > allowed %.3f m", lateral_3sigma,
                          options_.allowed_lateral_error_m)};
  }
  const double yaw_3sigma = 3.0 * std::sqrt(std::max(0.0, output.covariance(5, 5)));
  if (yaw_3sigma > options_.max_yaw_3sigma_rad) {
    return {false, Format("3-sigma yaw %.4f rad > allowed %.4f rad", yaw_3sigma,
                          options_.max_yaw_3sigma_rad)};
  }
  std::string reason = Format("3-sigma lateral %.3f m and yaw %.4f rad within limits",
                              lateral_3sigma, yaw_3sigma);
  if (output.seconds_since_vision > options_.max_vision_age_s) {
    char aided[64];
    std::snprintf(aided, sizeof(aided), " (DVL-aided: no vision for %.2f s)",
                  output.seconds_since_vision);
    reason += aided;
  }
  return {true, reason};
}

}  // namespace auvdock
