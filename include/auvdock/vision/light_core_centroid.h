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
// structure the halo touches (a lit funnel rim pulls a low-level centroid by pixels). A core that
// still reaches the window's edge at the highest level (a light clipped together with the
// structure it touches: overexposure) is cut from it by a morphological opening of its mask with
// a disc of radius k = neck_cut_sigmas sigma: a light's disc (radius ~sqrt(2) sigma at its blob
// scale) survives it, a neck or rim narrower than 2k does not. A core so separated is marked
// separated, and what the opening leaves of the junction may pull its centre towards the
// structure: its covariance grows by (separated_bias_fraction k)^2 per axis. Only at scales up to
// max_neck_cut_sigma_px: a larger opening carves lobes out of a structure itself (a white funnel's
// interior split by its vanes), and a light that large outshines any rim it touches.
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
  double neck_cut_sigmas = 0.7;  // 0: no separation
  double max_neck_cut_sigma_px = 16.0;
  double separated_bias_fraction = 0.25;
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
  bool separated = false;       // cut from a bright structure by the opening (see above)
  double separation_px = 0.0;   // the opening's radius k when separated
};

// luma: CV_32FC1. (x, y) the candidate pixel, sigma_px its scale, noise_sigma the image's pixel
// noise (gray levels). nullopt when the window holds no contrast (peak == floor).
std::optional<LightCore> MeasureLightCore(const cv::Mat& luma, int x, int y, double sigma_px,
                                          double noise_sigma, const LightCoreOptions& options);

}  // namespace auvdock
