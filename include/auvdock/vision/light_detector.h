// Finds the dock's guide lights (bright blue-green LED blobs) in one underwater image: seed 000's
// threshold + connected components + centroid (Zhu et al. 2025, section 2.1; its dark-channel
// dehazing is optional here) with seed 004's pre-filter, made robust to the haze, vignetting and
// lamp hot spot of close-range underwater images and to the two distractors of the simulator.
//
// TODO(detector): describe pipeline, measured results.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/vision/dark_channel_dehazer.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

enum class LightThreshold {
  kLocalContrast,  // contrast above the local background >= max(min_contrast, k sigma_noise)
  kOtsu,           // Otsu's cut of the background-subtracted image, floored by the above
};

struct LightDetectorOptions {
  bool dehaze = false;
  DehazeOptions dehaze_options;

  double prefilter_sigma_px = 1.0;
  int median_ksize = 0;

  int background_grid_cols = 80;
  int background_window_cells = 9;
  int colour_background_window_cells = 15;

  LightThreshold threshold = LightThreshold::kLocalContrast;
  double threshold_noise_sigmas = 6.0;
  double min_contrast = 4.0;
  double min_peak_contrast = 8.0;
  double min_prominence = 6.0;

  int min_area_px = 4;
  double max_area_fraction = 0.5;
  int coarse_scale = 4;
  int coarse_background_window_cells = 33;
  double coarse_min_sigma_px = 12.0;
  double max_elongation = 4.0;
  double min_contrast_per_sigma = 3.8;
  double min_clipped_contrast_per_sigma = 0.8;
  double max_unclipped_sigma_px = 10.0;

  double min_fit_contrast = 15.0;
  int max_fit_pixels = 400;
  double fit_taper_sigmas = 0.6;
  double max_fit_shift_sigmas = 0.8;
  double min_sigma_px = 0.7;
  bool model_reflections = true;

  bool reject_reflections = true;
  double reflection_min_offset_sigmas = 1.0;
  double reflection_max_offset_sigmas = 7.0;
  double reflection_max_offset_px = 8.0;
  double reflection_max_lateral_sigmas = 1.5;
  double reflection_max_ratio = 0.6;

  bool reject_particles = true;
  double particle_max_sigma_px = 4.0;
  double particle_min_red_ratio = 0.3;
};

class LightDetector {
 public:
  explicit LightDetector(const LightDetectorOptions& options = {});

  std::vector<LightDetection> Detect(const cv::Mat& bgr8) const;

  const LightDetectorOptions& options() const { return options_; }

 private:
  LightDetectorOptions options_;
  DarkChannelDehazer dehazer_;
};

}  // namespace auvdock
