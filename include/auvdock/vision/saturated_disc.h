// The centre of a light too close and too bright for a blob: a saturated disc.
//
// A light a few decimetres from the camera saturates a disc of tens to hundreds of pixels. Its
// blob response is flat over the disc (no peak at any scale the detector can afford) and the
// checks against lit surfaces reject it as "extended"; yet its centre is well defined. A
// saturated region (every channel at or above saturation_level: a white core, not the coloured
// glow around it; 8-connected) is measured as a light's disc when
//   - it lies inside the image and inside the searched window (not cut by the border, whose cut
//     would move the centre; not a saturated wall or sky),
//   - its equivalent radius sqrt(area / pi) is at least min_radius_px (smaller cores are the
//     blob detector's),
//   - a circle fits its outline: the circle (c, R) that the most outline pixels lie on, within
//     fit_tolerance_px of it, is supported by outline pixels within max(1 px,
//     arc_tolerance_fraction R) of it over at least min_arc_fraction of its circumference (one
//     outline pixel a pixel of arc),
//   - the region fills that circle (at least min_fill of the pixels within R + 1/2 of c) and does
//     not reach far beyond it (the pixels outside at most max_outside_fraction of the circle's).
// The circle, not the region's centroid, is the light: a reflection or a second glow merged into
// one side of the plateau (an egg-shaped region) pushes that side's outline out and leaves the
// rest of the light's circle in place, and the consensus takes the circle that most of the
// outline lies on. Two lights merged into one region reach far beyond either circle and are
// refused; so are a ring (a lit rim: the circle is not filled) and a bar (no circle holds its
// outline).
//
// Circle fit: candidate circles through three outline pixels a third, a quarter and a sixth of the
// outline apart, from starting pixels spread over the outline (deterministic); the best one's
// inliers refined by Gauss-Newton on the geometric distance |p_i - c| - R, twice (inliers again
// after the first). The fit's tolerance is a pixel (the outline's quantisation), so that it
// settles on the arc that is most exactly a circle: a reflection's glow pushes the outline out
// smoothly over half the disc or more, and a tolerance that grows with the disc takes that part
// in (on the renders' discs of radius >= 40 px under the landed camera, 2-3 px from the light
// instead of 4-6 px). The wider acceptance tolerance is for a real beam's outline, which is not
// a perfect circle. Outline pixel centres lie half a pixel inside the region's edge, so the
// disc's radius is R + 1/2.
//
// The detection is the circle's centre, that radius and an isotropic centroid covariance
// (centroid_sigma_fraction * radius + centroid_sigma_floor_px)^2: a disc's outline is shaped by
// the light's beam, the optics, the sensor's bloom and what merges into it, so the error grows
// with its size (a fifth of the radius: 24 px for a 120 px disc).
//
// Units: pixels (raw image; (0, 0) the centre of the top-left pixel).
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct SaturatedDiscOptions {
  int saturation_level = 250;
  double search_radius_px = 8.0;    // FindSaturatedDisc: how far from the seed the region may lie
  double window_radius_px = 300.0;  // FindSaturatedDisc: the searched window around the seed
  double min_radius_px = 6.0;
  double fit_tolerance_px = 1.0;
  double arc_tolerance_fraction = 0.03;
  double min_arc_fraction = 0.5;
  double min_fill = 0.9;
  double max_outside_fraction = 0.6;
  double centroid_sigma_fraction = 0.2;
  double centroid_sigma_floor_px = 0.5;
};

// The disc at or nearest seed_uv (within search_radius_px), in a window of window_radius_px
// around it. image: CV_8UC3 or CV_8UC1. Nothing when no region qualifies.
std::optional<LightDetection> FindSaturatedDisc(const cv::Mat& image,
                                                const Eigen::Vector2d& seed_uv,
                                                const SaturatedDiscOptions& options = {});

// Every saturated region of the whole image that qualifies as a disc (search_radius_px and
// window_radius_px unused), in no particular order.
std::vector<LightDetection> FindSaturatedDiscs(const cv::Mat& image,
                                               const SaturatedDiscOptions& options = {});

}  // namespace auvdock
