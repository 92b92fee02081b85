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

// The detection's own covariance (pixels^2) with every eigenvalue raised to at least
// floor_sigma_px^2; floor_sigma_px^2 I when it has none (all zero or not finite).
Eigen::Matrix2d PixelCovarianceAtLeast(const LightDetection& detection, double floor_sigma_px);

// The sigma a frame's detections typically claim: the median of sqrt(trace / 2) over those with
// a covariance, at least floor_sigma_px (the camera's pixel noise); floor_sigma_px if none has.
double TypicalPixelSigma(const std::vector<LightDetection>& detections, double floor_sigma_px);

// The covariance (pixels^2) a pose weighs a detection's centre with: typical_sigma_px^2 I,
// unless the detection claims more than doubt_ratio times that (sqrt(trace / 2): a light cut by
// the border, a core cut from a bright structure, a blob in another light's glow -- a bias it
// knows of), then its own covariance, every eigenvalue at least typical_sigma_px^2. The claims'
// finer differences (tenths of a pixel, from a core's shape or an interlaced smear) are not
// trusted to weigh one light above another: on the real pool clip weighing every light by its
// own claim cost LEDs and poses on its perturbed copies (README, "Each light's own covariance").
Eigen::Matrix2d PixelCovarianceForPose(const LightDetection& detection, double typical_sigma_px,
                                       double doubt_ratio = 2.0);

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
