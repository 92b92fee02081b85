#include "auvdock/estimator/vision_error_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>


namespace auvdock {

namespace {

using Sample = VisionErrorSample;
using TrackKey = VisionTrackKey;

// The residual's pixel-equivalent error at the problem's current values; false when it cannot
// be evaluated or is not finite.
bool EvaluateSample(const ceres::Problem& problem, const VisionResidual& r, Sample* sample) {
  Eigen::Vector3d whitened = Eigen::Vector3d::Zero();
  double cost = 0.0;
  if (!problem.EvaluateResidualBlock(r.id, /*apply_loss_function=*/false, &cost, whitened.data(),
                                     nullptr)) {
    return false;
  }
  const int m = r.mono ? 2 : 3;
  const Eigen::Vector3d e = whitened * r.pixel_sigma_px;
  if (!e.head(m).allFinite() || !(r.pixel_sigma_px > 0.0)) return false;
  *sample = {r.t_ns, e, r.pixel_sigma_px, m};
  return true;
}

// One state's residuals as pixel-equivalent errors, with the part a change of the state's pose
// could explain taken out: the whitened residuals r_i with their Jacobians J_i on the first
// parameter block (the pose, in its tangent space), r_i - J_i dx with dx the least-squares fit
// of all of them. What another sensor pulls the pose to (a depth offset, a DVL bias) moves every
// light the way a pose change does and is taken out; an offset of each light's own mostly
// stays. For offsets independent between the n coordinates, E[|r_perp|^2] = (1 - k / n) of
// theirs (least squares with k = rank(J) parameters): *kept_share. Empty when the fit leaves
// less than a quarter (too few lights to tell an offset of their own).
std::map<TrackKey, Sample> ProjectedSamples(const ceres::Problem& problem,
                                            const std::vector<VisionResidual>& residuals,
                                            double* kept_share) {
  struct Row {
    TrackKey key;
    Sample sample;
    Eigen::Matrix<double, 3, Eigen::Dynamic> J;  // whitened, m x k (unused rows zero)
    Eigen::Vector3d r;                           // whitened residual
  };
  std::vector<Row> rows;
  int k = -1;
  double coordinates = 0.0;
  for (const VisionResidual& r : residuals) {
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(r.id, &blocks);
    if (blocks.empty()) continue;
    const int tangent = problem.ParameterBlockTangentSize(blocks[0]);
    if (k != -1 && tangent != k) continue;  // not the same state's pose: left out
    Row row;
    row.r.setZero();
    Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> J_buffer(3, tangent);
    J_buffer.setZero();
    std::vector<double*> jacobians(blocks.size(), nullptr);
    jacobians[0] = J_buffer.data();
    double cost = 0.0;
    if (!problem.EvaluateResidualBlock(r.id, /*apply_loss_function=*/false, &cost, row.r.data(),
                                       jacobians.data())) {
      continue;
    }
    const int m = r.mono ? 2 : 3;
    const Eigen::Vector3d e = row.r * r.pixel_sigma_px;
    if (!e.head(m).allFinite() || !(r.pixel_sigma_px > 0.0) || !J_buffer.allFinite()) continue;
    k = tangent;
    row.key = {r.mono, r.sensor, r.light_id};
    row.sample = {r.t_ns, e, r.pixel_sigma_px, m};
    row.J = J_buffer;
    rows.push_back(std::move(row));
    coordinates += m;
  }
  std::map<TrackKey, Sample> samples;
  *kept_share = 1.0;
  if (rows.empty()) return samples;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(k);
  for (const Row& row : rows) {
    H += row.J.transpose() * row.J;
    g += row.J.transpose() * row.r;
  }
  // A pseudo-inverse: directions the lights do not observe are not fitted.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(H);
  const double largest = eigen.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(k);
  int rank = 0;
  for (int i = 0; i < k; ++i) {
    const double lambda = eigen.eigenvalues()(i);
    if (!(lambda > 1e-9 * largest)) continue;
    const Eigen::VectorXd v = eigen.eigenvectors().col(i);
    dx += v * (v.dot(g) / lambda);
    ++rank;
  }
  *kept_share = 1.0 - rank / coordinates;
  if (!(*kept_share >= 0.25)) return samples;
  for (Row& row : rows) {
    const Eigen::Vector3d r_perp = row.r - row.J * dx;
    row.sample.e = r_perp * row.sample.sigma;
    samples[row.key] = row.sample;
  }
  return samples;
}

}  // namespace

VisionErrorStatistics MeasureVisionErrors(const ceres::Problem& problem,
                                          const std::vector<VisionResidual>& residuals,
                                          int64_t max_gap_ns) {
  std::map<TrackKey, std::vector<Sample>> tracks;
  for (const VisionResidual& r : residuals) {
    Sample sample;
    if (EvaluateSample(problem, r, &sample)) {
      tracks[{r.mono, r.sensor, r.light_id}].push_back(sample);
    }
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

void SlowVisionError::Moments::Blend(const FrameSamples& earlier, const FrameSamples& later,
                                     int64_t max_gap_ns, double time_constant_frames) {
  // Each product divided by the shares the two fits left (their geometric mean), so that it
  // estimates the offset's variance, not what is left of it.
  const double share = std::sqrt(earlier.kept_share * later.kept_share);
  double sum = 0.0, weight = 0.0, pairs = 0.0, lag_sum = 0.0;
  for (const auto& [key, s] : later.samples) {
    const auto it = earlier.samples.find(key);
    if (it == earlier.samples.end()) continue;
    const Sample& p = it->second;
    if (s.t_ns - p.t_ns > max_gap_ns || s.t_ns <= p.t_ns || s.m != p.m) continue;
    sum += s.e.dot(p.e) / (s.sigma * p.sigma) / share;  // a mono residual's third entry is 0
    weight += s.m / (s.sigma * p.sigma);
    pairs += s.m;
    lag_sum += s.m * static_cast<double>(s.t_ns - p.t_ns) * 1e-9;
  }
  if (pairs == 0.0) return;
  // This frame's weighted mean lag product, blended in by its information against the frames'
  // mean information (a frame whose one light is a wide glow moves the estimate little), as a
  // plain mean over the first time_constant_frames frames and an exponential moving average
  // after.
  pairs_seen += pairs;
  frames_seen += 1.0;
  const double n = std::min(frames_seen, time_constant_frames);
  mean_weight += (weight - mean_weight) / n;
  const double alpha = std::min(1.0, weight / mean_weight / n);
  mean_product += alpha * (sum / weight - mean_product);
  mean_lag_s += alpha * (lag_sum / pairs - mean_lag_s);
}

void SlowVisionError::Add(const ceres::Problem& problem, const std::vector<VisionResidual>& newest,
                          int64_t max_gap_ns) {
  if (!options_.enabled) return;
  FrameSamples frame;
  frame.samples = ProjectedSamples(problem, newest, &frame.kept_share);
  if (!history_.empty()) {
    near_.Blend(history_.back(), frame, max_gap_ns, options_.time_constant_frames);
  }
  if (static_cast<int>(history_.size()) >= options_.far_lag_frames &&
      options_.far_lag_frames > 1) {
    far_.Blend(history_.front(), frame, max_gap_ns * options_.far_lag_frames,
               options_.time_constant_frames);
  }
  history_.push_back(std::move(frame));
  while (static_cast<int>(history_.size()) > std::max(1, options_.far_lag_frames)) {
    history_.pop_front();
  }
}

double SlowVisionError::slow_px() const {
  if (!options_.enabled || near_.pairs_seen < options_.min_pairs) return 0.0;
  return std::sqrt(std::max(0.0, near_.mean_product));
}

double SlowVisionError::correlation_time_s() const {
  if (!options_.enabled || near_.pairs_seen < options_.min_pairs ||
      far_.pairs_seen < options_.min_pairs || !(near_.mean_product > 0.0) ||
      !(far_.mean_lag_s > near_.mean_lag_s)) {
    return 0.0;
  }
  const double ratio = far_.mean_product / near_.mean_product;
  if (ratio >= 1.0) return std::numeric_limits<double>::infinity();
  if (!(ratio > 0.0)) return 0.0;
  return (far_.mean_lag_s - near_.mean_lag_s) / std::log(1.0 / ratio);
}

}  // namespace auvdock
