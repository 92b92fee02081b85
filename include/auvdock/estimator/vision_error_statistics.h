// The white and the slowly varying parts of the vision errors, measured from the residuals of a
// solved problem (the batch smoother's), so that the smoother's correlated-error model
// (estimator/batch_smoother.h) can follow the data instead of a configured figure.
//
// Model, per pixel coordinate: error = white part (sigma_w, independent from frame to frame) +
// slow part (sigma_s, autocorrelation exp(-|t| / tau) with tau much longer than the frame
// interval dt). Each residual is expressed in pixel-equivalent units, e = r_w * pixel_sigma_px
// (r_w whitened, without loss or stage weight; VisionResidual::pixel_sigma_px): the pixel error
// of a mono light, the point error in units of the stereo pair's pixel noise. The residuals of
// one light in one camera system form a track; over consecutive frames of the tracks
//   C0 = mean e_t^2          -> sigma_w^2 (1 - h_w) + sigma_s^2 (1 - h_s)
//   C1 = mean e_t e_{t+dt}   -> rho sigma_s^2 (1 - h_s),   rho = exp(-dt / tau) ~ 1,
// where h_w, h_s are the shares of each part that the states absorb (their leverage). A smoothed
// trajectory, tied by the IMU from frame to frame, absorbs little of the white part (h_w ~ the
// leverage of one frame among the many that fix a pose) but some of the slow part, all of it
// that moves every light of a camera alike. So
//   slow_px  = sqrt(C1)              a lower bound on sigma_s (what no state explains),
//   white_px = sqrt(max(0, C0 - C1)) about sigma_w.
// The means are information-weighted (1 / sigma^2 per coordinate, 1 / (sigma_t sigma_t+dt) per
// pair): the precise detections set the figures, not a few large glows with a sigma of their own.
// Measured on randomised renders (seed 1, lobes biasing each light by 0.1-0.3 px): white 0.14 px
// against 0.3 configured, slow 0.07-0.09 px, while the smoother's NEES showed the pose errors of
// a slow error about twice that: most of a light's bias goes into the pose, not the residual.
// So the figures are a diagnostic (summary.json `vision_errors`: is pixel_noise_px about
// right?), not a noise model to adapt to.
// Units: px. Only finite residuals of tracks with consecutive frames (gap <= max_gap_ns) count.
#pragma once

#include <cstdint>
#include <vector>

#include <ceres/problem.h>

#include "auvdock/estimator/vision_factors.h"

namespace auvdock {

struct VisionErrorStatistics {
  double white_px = 0.0;    // per coordinate (see above)
  double slow_px = 0.0;     // per coordinate, lower bound (see above)
  int64_t coordinates = 0;  // residual coordinates in C0
  int64_t lag_pairs = 0;    // coordinate pairs in C1; 0 = nothing measured (both figures 0)
};

// residuals: every vision residual still in the problem, any order.
VisionErrorStatistics MeasureVisionErrors(const ceres::Problem& problem,
                                          const std::vector<VisionResidual>& residuals,
                                          int64_t max_gap_ns);

}  // namespace auvdock
