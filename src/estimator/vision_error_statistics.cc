#include "auvdock/estimator/vision_error_statistics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include <Eigen/Core>

namespace auvdock {

VisionErrorStatistics MeasureVisionErrors(const ceres::Problem& problem,
                                          const std::vector<VisionResidual>& residuals,
                                          int64_t max_gap_ns) {
  struct Sample {
    int64_t t_ns;
    Eigen::Vector3d e;  // pixel-equivalent error
    double sigma;       // its pixel sigma
    int m;
  };
  using TrackKey = std::tuple<bool, std::string, int>;  // (mono, camera, light)
  std::map<TrackKey, std::vector<Sample>> tracks;
  for (const VisionResidual& r : residuals) {
    Eigen::Vector3d whitened = Eigen::Vector3d::Zero();
    double cost = 0.0;
    if (!problem.EvaluateResidualBlock(r.id, /*apply_loss_function=*/false, &cost,
                                       whitened.data(), nullptr)) {
      continue;
    }
    const int m = r.mono ? 2 : 3;
    const Eigen::Vector3d e = whitened * r.pixel_sigma_px;
    if (!e.head(m).allFinite() || !(r.pixel_sigma_px > 0.0)) continue;
    tracks[{r.mono, r.sensor, r.light_id}].push_back({r.t_ns, e, r.pixel_sigma_px, m});
  }
  // Information-weighted means (weights 1 / sigma^2, 1 / (sigma_t sigma_t+dt)): the precise
  // detections set the figures, not the few large glows whose own sigma already covers them.
  double sum0 = 0.0, weight0 = 0.0, sum1 = 0.0, weight1 = 0.0;
  VisionErrorStatistics stats;
  for (auto& [key, track] : tracks) {
    std::sort(track.begin(), track.end(),
              [](const Sample& a, const Sample& b) { return a.t_ns < b.t_ns; });
    for (size_t k = 0; k < track.size(); ++k) {
      const Sample& s = track[k];
      sum0 += s.e.head(s.m).squaredNorm() / (s.sigma * s.sigma);
      weight0 += s.m / (s.sigma * s.sigma);
      stats.coordinates += s.m;
      if (k == 0) continue;
      const Sample& p = track[k - 1];
      if (s.t_ns - p.t_ns > max_gap_ns || s.t_ns == p.t_ns) continue;
      sum1 += s.e.head(s.m).dot(p.e.head(s.m)) / (s.sigma * p.sigma);
      weight1 += s.m / (s.sigma * p.sigma);
      stats.lag_pairs += s.m;
    }
  }
  if (stats.lag_pairs == 0) return stats;  // nothing measured: both figures 0
  const double c0 = sum0 / weight0;
  const double c1 = sum1 / weight1;
  stats.slow_px = std::sqrt(std::max(0.0, c1));
  stats.white_px = std::sqrt(std::max(0.0, c0 - std::max(0.0, c1)));
  return stats;
}

}  // namespace auvdock
