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

// v = row[x] is not below any of its 8 neighbours in the image (above, below: the rows around
// it, nullptr at the image's edge).
bool NotBelowNeighbours(float v, const float* above, const float* row, const float* below, int x,
                        int cols) {
  const int x0 = std::max(0, x - 1), x1 = std::min(cols - 1, x + 1);
  for (int i = x0; i <= x1; ++i) {
    if ((above != nullptr && v < above[i]) || v < row[i] || (below != nullptr && v < below[i])) {
      return false;
    }
  }
  return true;
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
  // Float throughout: the 8-bit fixed-point blurs are no faster here (more instructions per
  // pixel on this OpenCV) and their quantisation makes spurious maxima.
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
      // Less than one pixel of that level of blur left: the level would alias the scale (at
      // 0.9 px the pool clip lost ~9 % of its posed frames).
      if (residual2 < pixel * pixel) break;
      if ((level0.cols >> (level + 1)) < 16 || (level0.rows >> (level + 1)) < 16) break;
      level = static_cast<int>(next);
    }
    return level;
  };

  // Responses at each scale's own pyramid level (level pixel j is full-resolution pixel
  // 2^level j: pyrDown's kernel is centred on the even pixels).
  std::vector<cv::Mat> responses(n);
  std::vector<int> levels(n);
  for (int k = 0; k < n; ++k) {
    const int level = level_for(sigmas[k]);
    levels[k] = level;
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
    // Laplacian per level pixel^2 -> per full-resolution pixel^2: divide by pixel^2.
    cv::Laplacian(blurred, responses[k], CV_32F, 1, -sigmas[k] * sigmas[k] / (pixel * pixel), 0.0,
                  cv::BORDER_REPLICATE);
  }
  // Response of scale k at a full-resolution point, bilinear on its level.
  auto sample = [&](int k, double x, double y) {
    const cv::Mat& r = responses[k];
    const double pixel = std::pow(2.0, levels[k]);
    const double gx = std::clamp(x / pixel, 0.0, r.cols - 1.0);
    const double gy = std::clamp(y / pixel, 0.0, r.rows - 1.0);
    const int x0 = std::min(static_cast<int>(gx), r.cols - 2 < 0 ? 0 : r.cols - 2);
    const int y0 = std::min(static_cast<int>(gy), r.rows - 2 < 0 ? 0 : r.rows - 2);
    const int x1 = std::min(x0 + 1, r.cols - 1), y1 = std::min(y0 + 1, r.rows - 1);
    const double ax = gx - x0, ay = gy - y0;
    return (1 - ay) * ((1 - ax) * r.at<float>(y0, x0) + ax * r.at<float>(y0, x1)) +
           ay * ((1 - ax) * r.at<float>(y1, x0) + ax * r.at<float>(y1, x1));
  };

  // Maxima over the 3 x 3 neighbourhood on the scale's own grid (neighbours outside the image do
  // not count), then not below the neighbouring scales at the same point (sampled on their
  // grids). Only points above the threshold are compared: most of an image is far below it.
  std::vector<BlobCandidate> found;
  const float threshold = static_cast<float>(options.min_response);
  const int last_scale = n > 1 && !options.keep_largest_scale ? n - 2 : n - 1;
  for (int k = 0; k <= last_scale; ++k) {
    const cv::Mat& r = responses[k];
    const int pixel = 1 << levels[k];
    for (int y = 0; y < r.rows; ++y) {
      const float* row = r.ptr<float>(y);
      const float* above = y > 0 ? r.ptr<float>(y - 1) : nullptr;
      const float* below = y + 1 < r.rows ? r.ptr<float>(y + 1) : nullptr;
      for (int x = 0; x < r.cols; ++x) {
        const float v = row[x];
        if (v < threshold || !NotBelowNeighbours(v, above, row, below, x, r.cols)) continue;
        const int fx = std::min(x * pixel, level0.cols - 1);
        const int fy = std::min(y * pixel, level0.rows - 1);
        if (k > 0 && v < sample(k - 1, fx, fy)) continue;
        if (k + 1 < n && v < sample(k + 1, fx, fy)) continue;
        found.push_back({fx, fy, sigmas[k], v});
      }
    }
  }
  std::sort(found.begin(), found.end(),
            [](const BlobCandidate& a, const BlobCandidate& b) { return a.response > b.response; });

  std::vector<BlobCandidate> kept;
  for (const BlobCandidate& c : found) {
    bool suppressed = false;
    for (const BlobCandidate& k : kept) {
      const double radius = std::max(options.nms_min_radius_px,
                                     options.nms_radius_sigmas * std::min(k.sigma_px, c.sigma_px));
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
