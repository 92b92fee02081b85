// The centre of a light too close and too bright for a blob: a saturated disc.
//
// A light a few decimetres from the camera saturates a disc of tens to hundreds of pixels. Its
// blob response is flat over the disc (no peak at any scale the detector can afford) and the
// checks against lit surfaces reject it as "extended"; yet its centre is well defined. Given a
// place where a pose predicts a light (seed_uv), the saturated region there (every channel at or
// above saturation_level: a white core, not the coloured glow around it; 8-connected) is taken
// as the light when
//   - it contains seed_uv or a pixel within search_radius_px of it,
//   - it lies inside the image and inside a window of window_radius_px around seed_uv (not
//     cut by the border, whose cut would move the centroid; not a saturated wall or sky),
//   - it is a filled, round disc: area >= min_fill of the ellipse of its second moments
//     (A = 4 pi sqrt(det Sigma) for a uniform ellipse), axis ratio <= max_axis_ratio,
//   - its equivalent radius sqrt(area / pi) is at least min_radius_px (smaller cores are the
//     blob detector's).
// The detection is the region's centroid, radius sqrt(area / pi) and an isotropic centroid
// covariance (centroid_sigma_fraction * radius)^2 + floor: a disc's outline is shaped by the
// light's beam, the optics and the sensor's bloom, so the error grows with its size (1/20 of the
// radius: 5 px for a 100 px disc).
//
// Units: pixels (raw image; (0, 0) the centre of the top-left pixel).
#pragma once

#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct SaturatedDiscOptions {
  int saturation_level = 250;
  double search_radius_px = 8.0;
  double window_radius_px = 300.0;
  double min_fill = 0.8;
  double max_axis_ratio = 1.6;
  double min_radius_px = 6.0;
  double centroid_sigma_fraction = 0.2;
  double centroid_sigma_floor_px = 0.5;
};

// image: CV_8UC3 or CV_8UC1. Nothing when no region qualifies.
std::optional<LightDetection> FindSaturatedDisc(const cv::Mat& image,
                                                const Eigen::Vector2d& seed_uv,
                                                const SaturatedDiscOptions& options = {});

}  // namespace auvdock
