// Synthetic light detections: what a front-end would report for one camera image, drawn from
// the lights the renderer would draw (UnderwaterRenderer::VisibleLights) without rendering or
// decoding an image. `simulate` writes them with `cameras.render_images: false`
// (DIR/detections.csv, io/detections_csv.h) so that `run` / `smooth --detections` and the
// Monte-Carlo audit (scripts/monte_carlo.sh) take a second or two per run instead of a minute.
//
// Error model (per camera; scenario key cameras.synthetic_detections):
//   u = pi(p_C) + b_i(view) + n,  n ~ N(0, pixel_noise_px^2 I)   (the camera's configured sigma)
//   b_i: a bias per light, as a light's asymmetric lobe gives (README "Vision noise"): magnitude
//        m_i bias_px with m_i ~ U[0.5, 1], direction phi_i + atan2(v - c_y, u - c_x) with
//        phi_i ~ U[0, 2 pi): it turns as the light moves across the image (view-dependent, slow).
//   each visible light is missed with miss_probability; the others are reported with their
//   identity (identified: true, as `auvdock frontend` writes them) or -1 (a bare detector),
//   a reported identity is another light's with wrong_id_probability; a Poisson number (mean
//   spurious_per_frame) of spurious light-like blobs, uniform over the image, id -1.
//   radius = 2 sigma of the drawn blob; score 1 for lights, U[0.3, 1) for spurious blobs.
// Every injected fault goes to groundtruth/faults.csv: "missed_light" (id), "wrong_id" (id and
// the reported one), "spurious_detection" (u, v). The detections of an image are shuffled (their
// order says nothing). With noise off (tests), detections are exact and no fault is injected.
// Frames: C camera (OpenCV); pixels in the raw (distorted) image.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/detections_csv.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/underwater_renderer.h"

namespace auvdock {

struct SyntheticDetectionConfig {
  double bias_px = 0.1;
  double miss_probability = 0.03;
  double spurious_per_frame = 0.3;
  double wrong_id_probability = 0.005;
  bool identified = true;
};

class SyntheticDetector {
 public:
  // The light biases are drawn here from rng, then every image's errors.
  SyntheticDetector(const SyntheticDetectionConfig& config, const CameraCalibration& camera,
                    const DockModel& dock, bool noisy, std::mt19937_64 rng);

  // The detections of one image at t_ns whose visible lights are `visible`; injected faults
  // are appended to *faults.
  ImageDetections Detect(int64_t t_ns, const std::vector<RenderedLight>& visible,
                         std::vector<FaultRecord>* faults);

 private:
  struct LightBias {
    int light_id = -1;
    double magnitude_px = 0.0;
    double phase_rad = 0.0;
  };
  Eigen::Vector2d Bias(int light_id, const Eigen::Vector2d& uv) const;

  SyntheticDetectionConfig config_;
  CameraCalibration camera_;
  std::vector<int> light_ids_;
  bool noisy_;
  std::mt19937_64 rng_;
  std::vector<LightBias> biases_;
};

// Number of events of a Poisson process with this mean, from uniform draws (Knuth; portable,
// so a seed gives the same dataset on every standard library).
int PoissonCount(double mean, std::mt19937_64& rng);

}  // namespace auvdock
