#include "auvdock/vision/blob_candidates.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

// Blur (full-resolution pixels) already carried by pyramid level l (level 0: none). pyrDown's
// 5-tap kernel has a standard deviation of ~1.08 pixels of the level it filters.
double PyramidBlur(int level) {
  double variance = 0.0;
  double pixel = 1.0;
  for (int l = 0; l < level; ++l) {
    variance += (1.08 * pixel) * (1.08 * pixel);
    pixel *= 2.0;
  }
  return std::sqrt(variance);
}

void CheckOptions(const BlobCandidateOptions& o) {
  if (!(o.min_sigma_px > 0.3) || !(o.max_sigma_px >= o.min_sigma_px) || o.num_scales < 1 ||
      o.num_scales > 32 || !(o.min_response >= 0.0) || !(o.nms_radius_sigmas >= 0.0) ||
      !(o.nms_min_radius_px >= 0.0) || o.max_candidates < 1) {
    throw std::invalid_argument("BlobCandidateOptions out of range");
  }
}

}  // namespace

std::vector<BlobCandidate> FindBlobCandidates(const cv::Mat& luma,
                                              const BlobCandidateOptions& options) {
  CheckOptions(options);
  if (luma.empty() || (luma.type() != CV_32FC1 && luma.type() != CV_8UC1)) {
    throw std::invalid_argument("FindBlobCandidates: expected a non-empty CV_32FC1 or CV_8UC1");
  }
  cv::Mat level0;
  luma.convertTo(level0, CV_32F);

  const int n = options.num_scales;
  std::vector<double> sigmas(n);
  for (int k = 0; k < n; ++k) {
    sigmas[k] = n == 1 ? options.min_sigma_px
                       : options.min_sigma_px *
                             std::pow(options.max_sigma_px / options.min_sigma_px,
                                      static_cast<double>(k) / (n - 1));
  }

  // Pyramid levels as far as the largest scale needs.
  std::vector<cv::Mat> pyramid{level0};
  auto level_for = [&](double sigma) {
    int level = 0;
    while (level < 4) {
      const double next = level + 1;
      const double pixel = std::pow(2.0, next);
      const double residual2 = sigma * sigma - PyramidBlur(level + 1) * PyramidBlur(level + 1);
      if (residual2 < pixel * pixel) break;  // less than one pixel of blur left at that level
      if ((level0.cols >> (level + 1)) < 16 || (level0.rows >> (level + 1)) < 16) break;
      level = static_cast<int>(next);
    }
    return level;
  };

  std::vector<cv::Mat> responses(n);
  for (int k = 0; k < n; ++k) {
    const int level = level_for(sigmas[k]);
    while (static_cast<int>(pyramid.size()) <= level) {
      cv::Mat down;
      cv::pyrDown(pyramid.back(), down);
      pyramid.push_back(down);
    }
    const double pixel = std::pow(2.0, level);
    const double residual =
        std::sqrt(std::max(0.0, sigmas[k] * sigmas[k] - PyramidBlur(level) * PyramidBlur(level))) /
        pixel;
    cv::Mat blurred;
    if (residual > 0.05) {
      cv::GaussianBlur(pyramid[level], blurred, cv::Size(0, 0), residual, residual,
                       cv::BORDER_REPLICATE);
    } else {
      blurred = pyramid[level];
    }
    cv::Mat laplacian;
    cv::Laplacian(blurred, laplacian, CV_32F, 1, 1.0, 0.0, cv::BORDER_REPLICATE);
    // Laplacian per level pixel^2 -> per full-resolution pixel^2: divide by pixel^2.
    const double scale = -sigmas[k] * sigmas[k] / (pixel * pixel);
    if (level == 0) {
      responses[k] = laplacian * scale;
    } else {
      // pyrDown puts level pixel j at full-resolution pixel pixel * j (its kernel is centred on
      // the even pixels), so full pixel x samples the level at x / pixel. cv::resize would
      // sample it at (x + 0.5) / pixel - 0.5 and shift every response by (pixel - 1) / 2 px.
      const cv::Matx23d full_to_level(1.0 / pixel, 0.0, 0.0, 0.0, 1.0 / pixel, 0.0);
      cv::Mat up;
      cv::warpAffine(laplacian, up, full_to_level, level0.size(),
                     cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
      responses[k] = up * scale;
    }
  }

  // Maxima over the 3 x 3 neighbourhood in space, then over the neighbouring scales.
  std::vector<cv::Mat> spatial_max(n);
  const cv::Mat kernel = cv::Mat::ones(3, 3, CV_8U);
  for (int k = 0; k < n; ++k) cv::dilate(responses[k], spatial_max[k], kernel);

  std::vector<BlobCandidate> found;
  const float threshold = static_cast<float>(options.min_response);
  for (int k = 0; k < n; ++k) {
    const cv::Mat& r = responses[k];
    for (int y = 0; y < r.rows; ++y) {
      const float* row = r.ptr<float>(y);
      const float* own = spatial_max[k].ptr<float>(y);
      const float* below = k > 0 ? spatial_max[k - 1].ptr<float>(y) : nullptr;
      const float* above = k + 1 < n ? spatial_max[k + 1].ptr<float>(y) : nullptr;
      for (int x = 0; x < r.cols; ++x) {
        const float v = row[x];
        if (v < threshold || v < own[x]) continue;
        if (below && v < below[x]) continue;
        if (above && v < above[x]) continue;
        found.push_back({x, y, sigmas[k], v});
      }
    }
  }
  std::sort(found.begin(), found.end(),
            [](const BlobCandidate& a, const BlobCandidate& b) { return a.response > b.response; });

  std::vector<BlobCandidate> kept;
  for (const BlobCandidate& c : found) {
    bool suppressed = false;
    for (const BlobCandidate& k : kept) {
      const double radius =
          std::max(options.nms_min_radius_px, options.nms_radius_sigmas * k.sigma_px);
      const double dx = c.x - k.x, dy = c.y - k.y;
      if (dx * dx + dy * dy < radius * radius) {
        suppressed = true;
        break;
      }
    }
    if (suppressed) continue;
    kept.push_back(c);
    if (static_cast<int>(kept.size()) >= options.max_candidates) break;
  }
  return kept;
}

}  // namespace auvdock
