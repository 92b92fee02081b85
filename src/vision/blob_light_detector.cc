#include "auvdock/vision/blob_light_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "auvdock/vision/field_deinterlace.h"
#include "auvdock/vision/image_levels.h"

namespace auvdock {
namespace {

double Clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

}  // namespace

BlobLightDetector::BlobLightDetector(const BlobLightDetectorOptions& options) : options_(options) {
  const auto& c = options.core;
  if (!(c.core_level > 0.0 && c.core_level < 1.0) || !(c.window_sigmas > 0.0) ||
      !(c.floor_percentile >= 0.0 && c.floor_percentile < 1.0) || !(c.shape_fraction >= 0.0) ||
      !(c.floor_px >= 0.0) || !(options.min_separation_px >= 0.0) ||
      !(options.border_sigma_fraction >= 0.0) || options.max_detections < 1 ||
      !(options.halo_extent_sigmas >= 0.0) || !(options.max_response_in_halo >= 0.0) ||
      !(options.checks.halo_radius_sigmas > 0.0) || !(options.checks.max_core_elongation >= 1.0) ||
      !(options.checks.max_core_stretch_px >= 0.0) || !(options.close_light_min_sigma_px > 0.0) ||
      !(options.checks.surroundings_halo_radii >= 0.0) ||
      !(options.checks.small_core_sigmas >= 0.0) ||
      !(options.checks.small_core_min_drop_fraction >= 0.0) ||
      !(options.checks.surroundings_quantile >= 0.0 && options.checks.surroundings_quantile <= 1.0) ||
      !(options.checks.min_own_colour_fraction >= 0.0 &&
        options.checks.min_own_colour_fraction <= 1.0)) {
    throw std::invalid_argument("BlobLightDetectorOptions out of range");
  }
  FindBlobCandidates(cv::Mat::zeros(16, 16, CV_32F), options.candidates);  // checks its options
}

std::vector<LightDetection> BlobLightDetector::Detect(const cv::Mat& image,
                                                      std::vector<RejectedLightCandidate>* rejected,
                                                      std::optional<double> min_halo_excess) const {
  if (image.empty() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) {
    throw std::invalid_argument("BlobLightDetector: expected a non-empty CV_8UC3 or CV_8UC1 image");
  }
  const cv::Mat source = options_.deinterlace ? LineDoubleEvenField(image) : image;
  cv::Mat gray;
  if (source.channels() == 3) {
    cv::cvtColor(source, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = source;
  }
  cv::Mat luma;
  gray.convertTo(luma, CV_32F);
  const double noise = EstimatePixelNoise(luma);
  const bool has_colour = source.channels() == 3;
  const double background_excess = MedianColourExcess(source, options_.checks.colour);

  struct Kept {
    LightDetection detection;
    double sigma;
    double response;
  };
  std::vector<Kept> kept;
  LightCandidateCheckOptions checks = options_.checks;
  if (min_halo_excess) checks.min_halo_excess = *min_halo_excess;
  // An image that clips below 255 (limited-range video, a gain past the clip) saturates there,
  // and its contrasts are those of a full-range image scaled by clip / 255.
  BlobCandidateOptions candidate_options = options_.candidates;
  double score_response = options_.score_response;
  const std::optional<double> clip =
      options_.adapt_to_clip_level ? EstimateClipLevel(gray, source) : std::nullopt;
  if (clip) {
    checks.saturation_level =
        std::min(checks.saturation_level, *clip - (255.0 - options_.checks.saturation_level));
    candidate_options.min_response *= std::min(1.0, *clip / 255.0);
    score_response *= std::min(1.0, *clip / 255.0);
  }
  // A threshold learned from the footage's lights (min_halo_excess) describes them at the
  // ranges they were seen at; a light within decimetres of the lens whitens its own halo
  // (saturated, blooming), so it is held to the permissive default only.
  LightCandidateCheckOptions close_checks = checks;
  close_checks.min_halo_excess = std::min(checks.min_halo_excess, options_.checks.min_halo_excess);
  std::vector<BlobCandidate> candidates = FindBlobCandidates(luma, candidate_options);
  std::stable_partition(candidates.begin(), candidates.end(), [&](const BlobCandidate& c) {
    return c.sigma_px <= options_.close_light_min_sigma_px;
  });
  for (const BlobCandidate& candidate : candidates) {
    auto reject = [&](const Eigen::Vector2d& uv, const std::string& reason) {
      if (rejected) rejected->push_back({uv, candidate.sigma_px, reason});
    };
    const Eigen::Vector2d at(candidate.x, candidate.y);
    const auto core =
        MeasureLightCore(luma, candidate.x, candidate.y, candidate.sigma_px, noise, options_.core);
    if (!core) {
      reject(at, "no contrast");
      continue;
    }
    const bool close_light = candidate.sigma_px > options_.close_light_min_sigma_px;
    const LightCandidateCheckOptions& candidate_checks = close_light ? close_checks : checks;
    const LightCandidateEvidence evidence = MeasureCandidateEvidence(
        source, luma, *core, candidate.sigma_px, background_excess, candidate_checks);
    const std::string reason =
        CheckLightCandidate(candidate, *core, evidence, has_colour, candidate_checks);
    if (!reason.empty()) {
      if (rejected) {
        // Only its colour failed (its shape passed): a light too close to show its colour.
        const bool colour_only =
            close_light && CheckLightCandidate(candidate, *core, evidence, /*has_colour=*/false,
                                               candidate_checks)
                               .empty();
        rejected->push_back({core->uv, candidate.sigma_px, reason, colour_only,
                             colour_only ? core->covariance : Eigen::Matrix2d::Zero()});
      }
      continue;
    }
    std::string overlap;
    for (const Kept& k : kept) {
      if (close_light &&
          (k.detection.uv - core->uv).norm() < options_.halo_extent_sigmas * candidate.sigma_px) {
        overlap = "larger than a light among lights";
        break;
      }
      const double distance = (k.detection.uv - core->uv).norm();
      const double separation =
          std::max({options_.min_separation_px, k.detection.radius_px, core->radius_px});
      if (distance < separation) {
        overlap = "duplicate";
        break;
      }
      if (distance < options_.halo_extent_sigmas * k.sigma &&
          candidate.response < options_.max_response_in_halo * k.response) {
        overlap = "in the halo of a brighter light";
        break;
      }
    }
    if (!overlap.empty()) {
      reject(core->uv, overlap);
      continue;
    }
    LightDetection d;
    d.uv = core->uv;
    d.radius_px = std::max(core->radius_px, candidate.sigma_px);
    d.peak = core->peak;
    const double strength = Clamp01(candidate.response / score_response);
    const double colour = has_colour && options_.checks.colour != LightColour::kWhite
                              ? Clamp01(evidence.halo_excess / (2.0 * checks.min_halo_excess))
                              : 1.0;
    d.score = std::sqrt(strength * colour);
    d.covariance = core->covariance;
    d.at_border = evidence.at_border;
    d.colour_excess = evidence.halo_excess;
    if (d.at_border) {
      const double s = options_.border_sigma_fraction * candidate.sigma_px;
      d.covariance += s * s * Eigen::Matrix2d::Identity();
    }
    kept.push_back({d, candidate.sigma_px, candidate.response});
  }
  std::vector<LightDetection> out;
  out.reserve(kept.size());
  for (const Kept& k : kept) out.push_back(k.detection);
  std::stable_sort(out.begin(), out.end(), [](const LightDetection& a, const LightDetection& b) {
    return a.score > b.score;
  });
  if (static_cast<int>(out.size()) > options_.max_detections) out.resize(options_.max_detections);
  return out;
}

}  // namespace auvdock
