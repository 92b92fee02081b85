// Finds the dock's guide lights (blue-green LED blobs) in one underwater image and measures their
// sub-pixel centres: seed 000's threshold + connected components + centroid (Zhu et al. 2025,
// section 2.1) and seed 004's pre-filter + threshold, made robust to what close-range underwater
// images add: haze, vignetting and the vehicle lamp's hot spot (a varying background), clipped
// light cores, the lights' reflections and marine snow.
//
// Pipeline (per image; pixel (0, 0) is the centre of the top-left pixel, as in OpenCV):
//  1. Luma (BT.601, cv::cvtColor) smoothed by a small Gaussian (prefilter_sigma_px; seed 004's
//     median filter is available as median_ksize, but it flattens small far lights and did not
//     help: recall, precision and RMS unchanged, 1.5 ms slower).
//  2. Local background: block means on a coarse grid (background_grid_cols cells across), closed
//     (max then min filter) with a window of background_close_cells cells, then opened (min then
//     max filter) with a window of background_window_cells cells, so that anything narrower than
//     the window - a light and its reflection - is not background while the haze gradient,
//     vignetting, the lamp's hot spot and the deck are. The closing fills the lights' dark
//     housings first: without it the opening's minimum sinks into them, the lamp-lit deck around
//     the lights rises above the threshold and merges with them (~20000 instead of ~2000 pixels
//     above the threshold on the benchmark frame: slower, and a light's blob then carries deck).
//  3. Threshold: smoothed luma > background + max(min_contrast, threshold_noise_sigmas x the
//     noise of the smoothed image), the noise estimated from neighbour differences. A fixed
//     contrast above the local background, not Otsu: a frame holds lights from 1 to 8 m whose
//     brightness spans two orders of magnitude, and Otsu's single cut between "bright" and the
//     rest drops the faint far ones (kOtsu, floored by the same contrast: turbid recall 0.98
//     instead of 1.0 on the test run); the light pixels are also too few (< 1 %) for a stable
//     Otsu split.
//  4. 8-connected components (union-find on the mask's runs), each split by flooding at its
//  significant maxima (rising at least
//     min_prominence above the saddle): two lights that touch become two blobs, while the
//     shoulder of a merged reflection stays with its light.
//  5. Per blob, the channel to measure in: the unclipped one with the most light, else the one
//     with the smallest clipped core (a blue-green light clips blue and green first; red then
//     carries its shape). A first centroid above half the peak, and sigma from that area.
//  6. Position: robust Levenberg-Marquardt fit of an isotropic Gaussian on a local quadratic
//     background in that channel, clipped pixels as inequalities, light added on top (a
//     neighbour, a particle) down-weighted by a one-sided Geman-McClure loss; for lights bright
//     enough for a reflection to show, a second fit with a dimmer, wider Gaussian below the light
//     (the reflection) in the model. The fit replaces the intensity-weighted centroid: over a
//     blob with a clipped core and a merged reflection the centroid is biased by up to several
//     pixels, the fit by ~0.1-0.3 px. Checks on the fit: it stays on its blob
//     (max_fit_shift_sigmas), explains the blob's centre, is at least min_sigma_px wide, and is
//     bright enough for its size (a light that looks big is near and therefore bright:
//     min_contrast_per_sigma; at the simulator's exposure every light bigger than
//     max_unclipped_sigma_px clips, lit deck and hot spots do not).
//  7. Distractors. Particles (marine snow): small (sigma <= particle_max_sigma_px) and white -
//     red as strong as blue-green (particle_min_red_ratio) - whereas a light that looks that small
//     is metres away and its red has been absorbed. Reflections: a blob directly below a fitted
//     light, within reflection_max_offset_sigmas sigmas (+ px), and dimmer than it in the light's
//     measuring channel (or unclipped where the light clips); recognised before fitting (lights
//     are fitted brightest first) and again after.
//  8. Lights too big for the background window (sigma above ~12 px at 640 px width, the last
//     metre of the landing) are found by the same steps on the image downsampled coarse_scale
//     times with a wide window, where the fine scale found nothing, and fitted at full size.
// Detections are sorted by score (contrast against the threshold, fit residual against the
// amplitude, size clear of the particle range), in [0, 1].
//
// Dehazing (seed 000's dark-channel enhancement, DarkChannelDehazer) is off by default: on the
// test run (default docking run, 3 cameras, every 4th frame) it lowered recall to 0.986-0.994,
// precision to 0.957-0.994 and raised the centroid RMS to 0.26-0.33 px in clear, coastal and
// turbid water, and costs ~1 ms per 640 x 512 frame. It rescales contrast by 1 / t, with t from a
// 15 px minimum filter that changes across a light's blob and halos around it; noise is scaled
// by the same gain, so it adds no signal, and the local background subtraction already does for
// detection what dehazing does for display.
//
// Measured on the simulator (tests/vision/light_detector_test.cc: default run, every 4th frame,
// 3 cameras, reflections, 3 particles per frame, noise; lights nearer than 8 m, matched within
// 2 px): clear water recall 1.0, precision 0.997, centroid RMS 0.187 px; turbid water recall
// 1.0, precision 1.0, RMS 0.198 px. Cost (benchmarks/vision_frontend_benchmark.cc BM_Detect, one
// core, stereo frame with 6 lights): ~1.2 ms at 640 x 512, ~3.2 ms at 1280 x 1024; the Gaussian
// fits (evaluated in float, four samples at a time) are about a third of it on the mono frame with
// a near light (model_reflections = false or coarse_scale = 0 trade accuracy or the last metre for
// speed). Fewer fit samples cost accuracy (max_fit_pixels 200: turbid RMS 0.27 px),
// and so does stopping the fits earlier (turbid RMS 0.21 px, one more false detection per water).
//
// Units: pixels and 8-bit gray levels. The sizes that stand for a range (coarse_min_sigma_px,
// max_unclipped_sigma_px and the pixel of sigma in min_contrast_per_sigma) are per 640 pixels of
// image width and scale with it, since a light's apparent size scales with the focal length;
// particle and blur sizes are sensor pixels. The detector is immutable after construction;
// Detect() is const and thread-safe.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/vision/dark_channel_dehazer.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

enum class LightThreshold {
  kLocalContrast,  // smoothed luma above the local background by the contrast threshold
  kOtsu,           // Otsu's cut of the background-subtracted image, floored by the above
};

struct LightDetectorOptions {
  bool dehaze = false;           // dark-channel dehazing first (see above: off, it hurts)
  DehazeOptions dehaze_options;  // seed 000: omega 0.5

  double prefilter_sigma_px = 1.0;  // Gaussian pre-filter of the luma; 0 = none
  int median_ksize = 0;             // seed 004's median pre-filter (odd, >= 3); 0 = none

  int background_grid_cols = 80;        // coarse background cells across the image
  int background_close_cells = 5;       // closing window first (fills dark housings); 0 = none
  int background_window_cells = 9;      // opening window, cells (72 px at 640 px width)
  LightThreshold threshold = LightThreshold::kLocalContrast;
  double threshold_noise_sigmas = 6.0;  // contrast threshold in noise sigmas of the smoothed luma
  double min_contrast = 4.0;            // ... and at least this, gray levels
  double min_peak_contrast = 8.0;       // a blob's peak above the background, gray levels
  double min_prominence = 6.0;          // a maximum separates two blobs if it rises this much
  int min_area_px = 4;                  // pixels above the threshold
  double max_area_fraction = 0.5;       // components larger than this share are background
  double max_elongation = 4.0;          // of the half-peak region (x 1.6 at the image border)

  int coarse_scale = 4;                     // downsampling of the big-light pass; 0 = no pass
  int coarse_background_window_cells = 33;  // its opening window, cells of the coarse grid
  double coarse_min_sigma_px = 12.0;        // only blobs at least this big come from that pass

  double min_fit_contrast = 15.0;  // an unclipped channel is measured in if it rises this much
  int max_fit_pixels = 400;        // samples per fit (the window is subsampled beyond)
  double fit_taper_sigmas = 0.6;   // below-light taper of the fit without the reflection term
  bool model_reflections = true;   // fit the reflection below bright lights (0.1-0.3 px better)
  double max_fit_shift_sigmas = 0.8;  // fit centre within this many sigmas of the first one
  double min_sigma_px = 0.7;          // sharper than the optics' blur is not a light
  double min_contrast_per_sigma = 3.8;          // gray levels per px of sigma (unclipped)
  double min_clipped_contrast_per_sigma = 0.8;  // ... for a blob whose core clips
  double max_unclipped_sigma_px = 10.0;         // bigger and unclipped is not a light; 0 = off

  bool reject_reflections = true;
  double reflection_min_offset_sigmas = 1.0;   // below the light by at least this
  double reflection_max_offset_sigmas = 7.0;   // ... and at most this many sigmas
  double reflection_max_offset_px = 8.0;       // ... plus this
  double reflection_max_lateral_sigmas = 1.5;  // sideways (+ 3 px)
  double reflection_max_ratio = 0.6;           // core brightness against the light's

  bool reject_particles = true;
  double particle_max_sigma_px = 4.0;   // a particle is at most this big ...
  double particle_min_red_ratio = 0.3;  // ... and this white: red / max(blue, green) excess
};

class LightDetector {
 public:
  // Throws std::invalid_argument for options out of range (negative sizes, empty grids).
  explicit LightDetector(const LightDetectorOptions& options = {});

  // The lights in an 8-bit BGR (CV_8UC3) or gray (CV_8UC1) image, by descending score. A gray
  // image has no colour: particles are then only rejected when sharper than min_sigma_px.
  // Throws std::invalid_argument for an empty image, another type, or a side over 65535 px.
  std::vector<LightDetection> Detect(const cv::Mat& bgr8) const;

  const LightDetectorOptions& options() const { return options_; }

 private:
  LightDetectorOptions options_;
  DarkChannelDehazer dehazer_;
};

}  // namespace auvdock
