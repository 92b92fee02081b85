#include "auvdock/sim/synthetic_detections.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "auvdock/io/csv.h"
#include "auvdock/sim/random_stream.h"

namespace auvdock {

namespace {

constexpr double kTwoPi = 6.283185307179586;

std::string Pixel(const Eigen::Vector2d& uv) {
  return "u=" + FormatDouble(std::round(uv.x() * 100) / 100) +
         ";v=" + FormatDouble(std::round(uv.y() * 100) / 100);
}

}  // namespace

int PoissonCount(double mean, std::mt19937_64& rng) {
  if (!(mean > 0.0)) return 0;
  const double limit = std::exp(-std::min(mean, 500.0));
  int k = 0;
  for (double p = Uniform01(rng); p > limit; p *= Uniform01(rng)) ++k;
  return k;
}

SyntheticDetector::SyntheticDetector(const SyntheticDetectionConfig& config,
                                     const CameraCalibration& camera, const DockModel& dock,
                                     bool noisy, std::mt19937_64 rng)
    : config_(config), camera_(camera), noisy_(noisy), rng_(std::move(rng)) {
  for (const DockLight& light : dock.lights) {
    light_ids_.push_back(light.id);
    LightBias bias;
    bias.light_id = light.id;
    bias.magnitude_px = Uniform(rng_, 0.5, 1.0) * config_.bias_px;
    bias.phase_rad = Uniform(rng_, 0.0, kTwoPi);
    biases_.push_back(bias);
  }
}

Eigen::Vector2d SyntheticDetector::Bias(int light_id, const Eigen::Vector2d& uv) const {
  for (const LightBias& b : biases_) {
    if (b.light_id != light_id) continue;
    const PinholeRadtanCamera& k = camera_.intrinsics;
    const double angle = b.phase_rad + std::atan2(uv.y() - k.cy(), uv.x() - k.cx());
    return b.magnitude_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  }
  return Eigen::Vector2d::Zero();
}

ImageDetections SyntheticDetector::Detect(int64_t t_ns, const std::vector<RenderedLight>& visible,
                                          std::vector<FaultRecord>* faults) {
  ImageDetections image;
  image.t_ns = t_ns;
  image.camera = camera_.name;
  const PinholeRadtanCamera& k = camera_.intrinsics;
  const double sigma = camera_.pixel_noise_px;
  for (const RenderedLight& light : visible) {
    if (noisy_ && Uniform01(rng_) < config_.miss_probability) {
      faults->push_back({t_ns, camera_.name, "missed_light", "id=" + std::to_string(light.light_id)});
      continue;
    }
    LightDetection d;
    d.uv = light.uv;
    if (noisy_) {
      d.uv += Bias(light.light_id, light.uv);
      d.uv += sigma * Eigen::Vector2d(StandardNormal(rng_), StandardNormal(rng_));
    }
    d.radius_px = 2.0 * light.radius_px;
    d.peak = std::min(255.0, light.peak);
    d.score = 1.0;
    d.at_border = !k.InImage(light.uv, light.radius_px * 3.0 + 1.0);
    int id = config_.identified ? light.light_id : -1;
    if (config_.identified && noisy_ && light_ids_.size() > 1 &&
        Uniform01(rng_) < config_.wrong_id_probability) {
      std::vector<int> others;
      for (int other : light_ids_) {
        if (other != light.light_id) others.push_back(other);
      }
      id = others[static_cast<size_t>(Uniform01(rng_) * static_cast<double>(others.size()))];
      faults->push_back({t_ns, camera_.name, "wrong_id",
                         "id=" + std::to_string(light.light_id) + ";reported=" +
                             std::to_string(id)});
    }
    image.detections.push_back(d);
    image.light_ids.push_back(id);
  }
  const int n_spurious = noisy_ ? PoissonCount(config_.spurious_per_frame, rng_) : 0;
  for (int s = 0; s < n_spurious; ++s) {
    LightDetection d;
    d.uv = Eigen::Vector2d(Uniform(rng_, 0.0, k.width() - 1.0), Uniform(rng_, 0.0, k.height() - 1.0));
    d.radius_px = Uniform(rng_, 1.5, 6.0);
    d.peak = Uniform(rng_, 60.0, 255.0);
    d.score = Uniform(rng_, 0.3, 1.0);
    faults->push_back({t_ns, camera_.name, "spurious_detection", Pixel(d.uv)});
    image.detections.push_back(d);
    image.light_ids.push_back(-1);
  }
  // Shuffled (Fisher-Yates on our own uniform draws: portable).
  std::vector<size_t> order(image.detections.size());
  std::iota(order.begin(), order.end(), 0);
  for (size_t i = order.size(); noisy_ && i > 1; --i) {
    const size_t j = std::min(i - 1, static_cast<size_t>(Uniform01(rng_) * static_cast<double>(i)));
    std::swap(order[i - 1], order[j]);
  }
  ImageDetections shuffled = image;
  for (size_t i = 0; i < order.size(); ++i) {
    shuffled.detections[i] = image.detections[order[i]];
    shuffled.light_ids[i] = image.light_ids[order[i]];
  }
  return shuffled;
}

}  // namespace auvdock
