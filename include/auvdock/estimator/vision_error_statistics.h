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
//
// SlowVisionError is the same C1 for the sliding window, online: after each solve it pairs the
// residuals of the newest state with those of the previous frame (the same light in the same
// camera system) and keeps an exponential moving average of the information-weighted lag
// products over time_constant_frames frames. Each state's residuals
// are taken right after its own solve, with the part a change of its pose could explain taken
// out (a projection on the pose Jacobians: what another sensor pulls the pose to moves every
// light as a pose change does), and each product is divided by the share of an offset such a
// fit leaves, 1 - 6 / n for n coordinates, so that sqrt(C1) estimates the slow error rather
// than what is left of it. The window takes it as its floor (window_vision_floor_px)
// when it is larger than the configured one, so that the allowance for slow errors follows
// views whose biases nobody configured. Pairs with the frame far_lag_frames before (a default
// window's span) give the slow part's decay, and so its correlation time. Each frame's
// residuals are evaluated once, when it is the newest.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Core>

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

struct SlowVisionErrorOptions {
  bool enabled = true;
  double time_constant_frames = 200.0;  // frames with pairs (20 s at 10 Hz), each weighted by
                                        // its information against the frames' mean
  double min_pairs = 200.0;             // coordinate pairs seen before slow_px() is other than 0
  int far_lag_frames = 9;               // the second lag, in frames (a default window's span)
};

// One residual as a pixel-equivalent error (whitened residual x its pixel sigma).
struct VisionErrorSample {
  int64_t t_ns = 0;
  Eigen::Vector3d e = Eigen::Vector3d::Zero();  // px (a mono residual's third entry 0)
  double sigma = 1.0;                           // its pixel sigma
  int m = 2;                                    // 2 (mono) or 3 (stereo)
};
using VisionTrackKey = std::tuple<bool, std::string, int>;  // (mono, camera, light id)

class SlowVisionError {
 public:
  explicit SlowVisionError(const SlowVisionErrorOptions& options = {}) : options_(options) {}

  // The newest state's vision residuals, still in the problem, right after its solve. They are
  // paired with the previous frame's (C1; pairs further apart than max_gap_ns are not counted)
  // and with those of far_lag_frames frames before (C_L).
  void Add(const ceres::Problem& problem, const std::vector<VisionResidual>& newest,
           int64_t max_gap_ns);

  // sqrt(max(0, C1)) once min_pairs coordinate pairs were seen; 0 before, or when disabled.
  double slow_px() const;
  // The slow part's correlation time (s) from the decay between the two lags, C_L / C1 =
  // exp(-(lag_L - lag_1) / tau): infinite when it does not decay (constant biases), 0 when
  // nothing is known yet (or C1 <= 0).
  double correlation_time_s() const;
  double pairs_seen() const { return near_.pairs_seen; }

 private:
  struct FrameSamples {
    std::map<VisionTrackKey, VisionErrorSample> samples;
    double kept_share = 1.0;  // the share of an offset the pose fit left in them
  };
  struct Moments {
    double mean_product = 0.0;  // EMA of the weighted lag products per weight (px^2)
    double mean_weight = 0.0;   // EMA of a frame's weight, sum of m / (sigma sigma') (1/px^2)
    double mean_lag_s = 0.0;    // EMA of the pairs' time lag (s)
    double pairs_seen = 0.0;
    double frames_seen = 0.0;
    // Blends in the lag products between two frames' samples.
    void Blend(const FrameSamples& earlier, const FrameSamples& later, int64_t max_gap_ns,
               double time_constant_frames);
  };
  SlowVisionErrorOptions options_;
  std::deque<FrameSamples> history_;  // the last far_lag_frames frames, oldest first
  Moments near_;  // newest against previous
  Moments far_;   // newest against far_lag_frames before
};

}  // namespace auvdock
