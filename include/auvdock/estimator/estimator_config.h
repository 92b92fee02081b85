// Options of `auvdock run` / `auvdock smooth` from a YAML file (--config), strict: every key is
// optional and defaults to the EstimatorOptions / GoNoGoOptions value; an unknown key, a wrong
// type or a value out of range is an InputError naming the file and the key. Example:
//
//   estimator:
//     window_size: 10
//     max_solver_iterations: 10
//     max_solver_time_s: 0.0          # 0 = no limit
//     solver_cost_tolerance: 0.01     # a solve stops when a step lowers the cost by less
//     huber_sigmas: 2.5
//     mono_gate_chi2: 13.82
//     stereo_gate_chi2: 16.27
//     max_imu_gap_s: 0.1
//     use_mono: true
//     use_stereo: true
//     stage_weighting: information     # or paper_light_count
//     smoother_vision_floor_px: 0.075  # batch smoother: slow part of the pixel errors; 0 = white
//     smoother_vision_correlation_time_s: 2.0
//     window_vision_floor_px: 0.07     # sliding window: the same model; 0 = white errors only
//     window_vision_correlation_time_s: 1.0
//     adaptive_vision_floor: true      # raise it to the slow error the residuals show
//   go_no_go:
//     allowed_lateral_error_m: 0.10
//     max_yaw_3sigma_rad: 0.05
//     max_vision_age_s: 0.5
//     max_gating_rate: 0.3
//     gating_window_frames: 20
#pragma once

#include <string>

#include "auvdock/estimator/go_no_go.h"
#include "auvdock/estimator/sliding_window_estimator.h"

namespace auvdock {

struct RunConfig {
  EstimatorOptions estimator;
  GoNoGoOptions go_no_go;
};

// Throws InputError for a missing or malformed file.
RunConfig LoadRunConfig(const std::string& path);

}  // namespace auvdock
