// A guide light found in one image, and the identity the matchers assign to it.
//
// uv: intensity-weighted sub-pixel centroid in the raw (distorted) image, pixels, with (0, 0)
// the centre of the top-left pixel (OpenCV). radius_px: equivalent radius sqrt(area / pi) of
// the blob above threshold. peak: maximum gray level (0-255) in the blob. score: detection
// confidence in [0, 1] from the size, shape and brightness checks (1 = a perfect light).
// covariance: the centre's own 2 x 2 covariance (pixels^2) when the detector measures one (all
// zero when it does not: the camera's pixel_noise_px then applies). at_border: the light's halo
// is cut by the image border, which biases its centre. colour_excess: how strongly the halo shows
// the light's colour against the image's median, gray levels (0 when not measured).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace auvdock {

struct LightDetection {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  double peak = 0.0;
  double score = 0.0;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  bool at_border = false;
  double colour_excess = 0.0;
};

// The covariance (pixels^2) that a pose weighs this detection's centre with: its own, with
// every eigenvalue raised to at least floor_sigma_px^2 (the camera's pixel noise: no centre is
// trusted beyond it); floor_sigma_px^2 I when it has none (all zero or not finite).
Eigen::Matrix2d PixelCovarianceAtLeast(const LightDetection& detection, double floor_sigma_px);

// One detection assigned to one dock light.
struct LightMatch {
  int detection = -1;  // index into the detections of the image
  int light_id = -1;   // DockLight::id
};

enum class MatchStatus {
  kOk,         // a unique, verified assignment
  kAmbiguous,  // two or more assignments explain the image about equally well: not used
  kFailed,     // no assignment explains the image (too few lights, no consensus)
};

const char* MatchStatusName(MatchStatus status);

struct MatchResult {
  MatchStatus status = MatchStatus::kFailed;
  std::vector<LightMatch> matches;  // empty unless kOk
  std::string reason;               // why not kOk, for logs and "no pose" results
  double cost = 0.0;                // matcher-specific: mean cost or RMS reprojection error (px)
};

}  // namespace auvdock
