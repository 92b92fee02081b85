// Sub-pixel centre of a light's core and its covariance.
//
// The core is the 8-connected region, around the brightest pixel near the candidate, of the
// pixels whose luma is at least  floor + core_level (peak - floor), where floor is a low
// percentile (floor_percentile) of the window of radius max(window_sigmas sigma, min_window_px)
// and peak its maximum. A saturated core is the clipped plateau; an unclipped one the top of the
// lobe. The centre is the weighted centroid with weights w_i = I_i - threshold:
//   c = sum w_i x_i / W,  W = sum w_i.
// When that core reaches the window's edge it has run into a bright structure beside the light
// (a lit funnel rim): the level is raised to (1 + core_level) / 2, then (3 + core_level) / 4.
// A high core_level keeps the centre on the emitting core and off the halo and any bright
// structure the halo touches (a lit funnel rim pulls a low-level centroid by pixels).
//
// Covariance (pixels^2), three parts:
//   * pixel noise: sigma_n^2 sum (x_i - c)(x_i - c)^T / W^2 (the centroid's linear error
//     propagation with white noise sigma_n per pixel);
//   * shape: shape_fraction^2 M, with M = sum w_i (x_i - c)(x_i - c)^T / W the core's second
//     moment: an asymmetric lobe, smear or combing moves the centroid in proportion to the core's
//     extent and in its long direction (a round 5 px core at 0.15 -> ~0.4 px per axis);
//   * floor_px^2 I (JPEG blocks, quantisation).
// Units: pixels (0, 0 is the centre of the top-left pixel), gray levels.
#pragma once

#include <optional>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <opencv2/core.hpp>

namespace auvdock {

struct LightCoreOptions {
  double core_level = 0.85;       // fraction of the way from the window floor to the peak
  double window_sigmas = 2.0;     // window radius in blob sigmas
  double min_window_px = 4.0;
  double floor_percentile = 0.2;  // of the window's pixels
  double search_sigmas = 1.0;     // the brightest pixel within this of the candidate
  double shape_fraction = 0.15;
  double floor_px = 0.1;
};

struct LightCore {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
  double peak = 0.0;       // gray levels
  double floor = 0.0;      // gray levels
  int area_px = 0;         // pixels in the core
  double radius_px = 0.0;  // sqrt(area / pi)
  // sqrt of the ratio of the eigenvalues of the core pixels' second moment (1: round; a 2:1
  // ellipse 2).
  double elongation = 1.0;
  bool touches_window = false;  // the core reaches the window's edge (not a compact core)
  bool touches_border = false;  // the core reaches the image's edge (cut: its centre is biased)
};

// luma: CV_32FC1. (x, y) the candidate pixel, sigma_px its scale, noise_sigma the image's pixel
// noise (gray levels). nullopt when the window holds no contrast (peak == floor).
std::optional<LightCore> MeasureLightCore(const cv::Mat& luma, int x, int y, double sigma_px,
                                          double noise_sigma, const LightCoreOptions& options);

}  // namespace auvdock
