#include "auvdock/sim/image_blobs.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace auvdock {

void AddGaussianBlob(const Eigen::Vector2d& uv, double sigma, const Eigen::Vector3d& amplitude_bgr,
                     cv::Mat* image) {
  const double amplitude_max = amplitude_bgr.maxCoeff();
  if (!(amplitude_max > 0.0) || !(sigma > 0.0)) return;
  const double support =
      sigma * std::max(4.0, std::sqrt(2.0 * std::log(std::max(1.0, 4.0 * amplitude_max))));
  const int u0 = std::max(0, static_cast<int>(std::ceil(uv.x() - support)));
  const int u1 = std::min(image->cols - 1, static_cast<int>(std::floor(uv.x() + support)));
  const int v0 = std::max(0, static_cast<int>(std::ceil(uv.y() - support)));
  const int v1 = std::min(image->rows - 1, static_cast<int>(std::floor(uv.y() + support)));
  if (u0 > u1 || v0 > v1) return;
  const double inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
  const double support2 = support * support;
  std::vector<double> gx(u1 - u0 + 1);
  for (int u = u0; u <= u1; ++u) {
    const double dx = u - uv.x();
    gx[u - u0] = std::exp(-dx * dx * inv_two_sigma2);
  }
  const float b = static_cast<float>(amplitude_bgr[0]);
  const float g = static_cast<float>(amplitude_bgr[1]);
  const float r = static_cast<float>(amplitude_bgr[2]);
  for (int v = v0; v <= v1; ++v) {
    const double dy = v - uv.y();
    const double dy2 = dy * dy;
    const double gy = std::exp(-dy2 * inv_two_sigma2);
    float* row = image->ptr<float>(v);
    for (int u = u0; u <= u1; ++u) {
      const double dx = u - uv.x();
      if (dx * dx + dy2 > support2) continue;
      const float weight = static_cast<float>(gx[u - u0] * gy);
      float* pixel = row + 3 * u;
      pixel[0] += b * weight;
      pixel[1] += g * weight;
      pixel[2] += r * weight;
    }
  }
}

void AddVerticalSmear(const Eigen::Vector2d& uv, double sigma, const Eigen::Vector3d& amplitude_bgr,
                      cv::Mat* image) {
  const int u0 = std::max(0, static_cast<int>(std::ceil(uv.x() - 3.0 * sigma)));
  const int u1 = std::min(image->cols - 1, static_cast<int>(std::floor(uv.x() + 3.0 * sigma)));
  for (int v = 0; v < image->rows; ++v) {
    const double wv = std::exp(-std::fabs(v - uv.y()) / (40.0 * sigma));
    float* row = image->ptr<float>(v);
    for (int u = u0; u <= u1; ++u) {
      const double du = u - uv.x();
      const double w = wv * std::exp(-du * du / (2.0 * sigma * sigma));
      for (int ch = 0; ch < 3; ++ch) row[3 * u + ch] += static_cast<float>(w * amplitude_bgr[ch]);
    }
  }
}

}  // namespace auvdock
