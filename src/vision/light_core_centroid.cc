#include "auvdock/vision/light_core_centroid.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace auvdock {

std::optional<LightCore> MeasureLightCore(const cv::Mat& luma, int x, int y, double sigma_px,
                                          double noise_sigma, const LightCoreOptions& options) {
  const int radius = static_cast<int>(
      std::ceil(std::max(options.window_sigmas * sigma_px, options.min_window_px)));
  const int x0 = std::max(0, x - radius), x1 = std::min(luma.cols - 1, x + radius);
  const int y0 = std::max(0, y - radius), y1 = std::min(luma.rows - 1, y + radius);
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  if (w < 2 || h < 2) return std::nullopt;

  std::vector<float> values;
  values.reserve(static_cast<size_t>(w) * h);
  for (int yy = y0; yy <= y1; ++yy) {
    const float* row = luma.ptr<float>(yy);
    values.insert(values.end(), row + x0, row + x1 + 1);
  }
  std::vector<float> sorted = values;
  const size_t k =
      std::min(sorted.size() - 1, static_cast<size_t>(options.floor_percentile * sorted.size()));
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  const double floor = sorted[k];

  // Seed: the brightest pixel within search_sigmas of the candidate.
  const double search = std::max(1.0, options.search_sigmas * sigma_px);
  int sx = x - x0, sy = y - y0;
  float best = -1.0f;
  for (int yy = 0; yy < h; ++yy) {
    for (int xx = 0; xx < w; ++xx) {
      const double dx = xx + x0 - x, dy = yy + y0 - y;
      if (dx * dx + dy * dy > search * search) continue;
      const float v = values[yy * w + xx];
      if (v > best) {
        best = v;
        sx = xx;
        sy = yy;
      }
    }
  }
  const double peak = best;
  if (!(peak > floor)) return std::nullopt;
  // Flood fill (8-connected) from the seed over pixels at or above the threshold (and, when
  // given, inside a mask); a core that reaches the window's edge has run into a bright structure
  // next to the light (a lit funnel rim): the level rises towards the peak until the core is
  // compact.
  LightCore core;
  std::vector<int> members;
  std::vector<unsigned char> in_core(values.size(), 0);
  auto flood = [&](int seed, double threshold, const cv::Mat& allowed) {
    std::fill(in_core.begin(), in_core.end(), 0);
    members.clear();
    core.touches_window = false;
    core.touches_border = false;
    std::vector<int> stack{seed};
    in_core[seed] = 1;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      members.push_back(i);
      const int xx = i % w, yy = i / w;
      if (xx + x0 == 0 || yy + y0 == 0 || xx + x0 == luma.cols - 1 || yy + y0 == luma.rows - 1) {
        core.touches_border = true;
      }
      // The window's edge, where it is not the image's (a core cut by the border is not big).
      if ((xx == 0 && x0 > 0) || (yy == 0 && y0 > 0) || (xx == w - 1 && x1 < luma.cols - 1) ||
          (yy == h - 1 && y1 < luma.rows - 1)) {
        core.touches_window = true;
      }
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = xx + dx, ny = yy + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const int j = ny * w + nx;
          if (in_core[j] || values[j] < threshold) continue;
          if (!allowed.empty() && !allowed.at<unsigned char>(ny, nx)) continue;
          in_core[j] = 1;
          stack.push_back(j);
        }
      }
    }
  };
  double threshold = 0.0;
  for (const double level :
       {options.core_level, 0.5 * (1.0 + options.core_level), 0.25 * (3.0 + options.core_level)}) {
    threshold = floor + level * (peak - floor);
    flood(sy * w + sx, threshold, cv::Mat());
    if (!core.touches_window) break;
  }
  if (core.touches_window && options.neck_cut_sigmas > 0.0 &&
      sigma_px <= options.max_neck_cut_sigma_px) {
    // Still joined to a structure at the highest level (both clipped, or the light's plateau
    // running into a lit rim): open the core mask with a disc of radius neck_cut_sigmas sigma,
    // which cuts necks and rims narrower than its diameter and keeps a disc of the light's size.
    cv::Mat mask(h, w, CV_8U);
    for (int i = 0; i < w * h; ++i) mask.data[i] = values[i] >= threshold ? 255 : 0;
    const int k = std::max(1, static_cast<int>(std::lround(options.neck_cut_sigmas * sigma_px)));
    cv::Mat opened;
    cv::morphologyEx(mask, opened, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * k + 1, 2 * k + 1)));
    // The opened pixel nearest the seed, within the search radius.
    int seed = -1;
    double nearest = search * search;
    for (int yy = 0; yy < h; ++yy) {
      for (int xx = 0; xx < w; ++xx) {
        if (!opened.at<unsigned char>(yy, xx)) continue;
        const double d2 = (xx - sx) * (xx - sx) + (yy - sy) * (yy - sy);
        if (d2 <= nearest) {
          nearest = d2;
          seed = yy * w + xx;
        }
      }
    }
    if (seed >= 0) {
      const std::vector<int> joined = members;
      const bool joined_border = core.touches_border;
      flood(seed, threshold, opened);
      if (core.touches_window) {
        members = joined;  // not separable: the joined core stands, and is judged extended
        core.touches_window = true;
        core.touches_border = joined_border;
      } else {
        core.separated = true;
        core.separation_px = k;
      }
    }
  }
  double sw = 0.0, su = 0.0, sv = 0.0;
  // Weights above the threshold; a flat (clipped) core gets a small uniform weight so that its
  // plateau counts as a whole.
  const double epsilon = std::max(1e-3, 0.02 * (peak - floor));
  for (int i : members) {
    const double wi = values[i] - threshold + epsilon;
    sw += wi;
    su += wi * (i % w + x0);
    sv += wi * (i / w + y0);
  }
  core.uv = Eigen::Vector2d(su / sw, sv / sw);
  Eigen::Matrix2d noise_term = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d moment = Eigen::Matrix2d::Zero();
  for (int i : members) {
    const double wi = values[i] - threshold + epsilon;
    const Eigen::Vector2d d(i % w + x0 - core.uv.x(), i / w + y0 - core.uv.y());
    noise_term += d * d.transpose();
    moment += wi * d * d.transpose();
  }
  moment /= sw;
  // A single pixel still has the extent of a pixel (uniform over its square: 1/12 per axis).
  moment += Eigen::Matrix2d::Identity() / 12.0;
  core.covariance = noise_sigma * noise_sigma * noise_term / (sw * sw) +
                    options.shape_fraction * options.shape_fraction * moment +
                    options.floor_px * options.floor_px * Eigen::Matrix2d::Identity();
  if (core.separated) {
    // What the opening left of the junction with the structure pulls the centre towards it by a
    // fraction of the opening's radius.
    const double s = options.separated_bias_fraction * core.separation_px;
    core.covariance += s * s * Eigen::Matrix2d::Identity();
  }
  core.peak = peak;
  core.floor = floor;
  core.area_px = static_cast<int>(members.size());
  core.radius_px = std::sqrt(core.area_px / 3.14159265358979323846);
  // Unweighted second moment of the member pixels: the core's outline, whatever its weights.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> outline(
      noise_term / static_cast<double>(members.size()) + Eigen::Matrix2d::Identity() / 12.0);
  core.elongation = std::sqrt(outline.eigenvalues()(1) / outline.eigenvalues()(0));
  return core;
}

}  // namespace auvdock
