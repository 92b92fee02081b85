#include "auvdock/vision/light_detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A channel whose maximum in a blob reaches this is clipped there (the sensor's full scale).
constexpr int kSaturatedLevel = 250;
constexpr int kFullScale = 255;

// Per-channel background on a coarse grid: block means, then a grey opening (erosion followed by
// dilation) that removes every bright structure narrower than the window, then a 3 x 3 mean.
// Sampled bilinearly at full-resolution pixel centres.
class CoarseBackground {
 public:
  CoarseBackground(const cv::Mat& image, int grid_cols, int window_cells) {
    cols_ = std::max(2, std::min(grid_cols, image.cols));
    cell_x_ = static_cast<double>(image.cols) / cols_;
    rows_ = std::max(2, static_cast<int>(std::lround(image.rows / cell_x_)));
    rows_ = std::min(rows_, image.rows);
    cell_y_ = static_cast<double>(image.rows) / rows_;
    cv::Mat coarse;
    cv::resize(image, coarse, cv::Size(cols_, rows_), 0, 0, cv::INTER_AREA);
    coarse.convertTo(coarse, CV_32F);
    const int w = std::max(1, window_cells);
    cv::morphologyEx(coarse, coarse, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_RECT, cv::Size(w, w)));
    cv::blur(coarse, coarse, cv::Size(3, 3), cv::Point(-1, -1), cv::BORDER_REPLICATE);
    cv::split(coarse, planes_);
  }

  int channels() const { return static_cast<int>(planes_.size()); }
  const cv::Mat& plane(int channel) const { return planes_[channel]; }

  double At(int channel, double x, double y) const {
    const double gx = std::clamp((x + 0.5) / cell_x_ - 0.5, 0.0, cols_ - 1.0);
    const double gy = std::clamp((y + 0.5) / cell_y_ - 0.5, 0.0, rows_ - 1.0);
    const int x0 = std::min(static_cast<int>(gx), cols_ - 2);
    const int y0 = std::min(static_cast<int>(gy), rows_ - 2);
    const double ax = gx - x0;
    const double ay = gy - y0;
    const cv::Mat& p = planes_[channel];
    const float* r0 = p.ptr<float>(y0);
    const float* r1 = p.ptr<float>(y0 + 1);
    return (1.0 - ay) * ((1.0 - ax) * r0[x0] + ax * r0[x0 + 1]) +
           ay * ((1.0 - ax) * r1[x0] + ax * r1[x0 + 1]);
  }

 private:
  std::vector<cv::Mat> planes_;
  int cols_ = 0, rows_ = 0;
  double cell_x_ = 1.0, cell_y_ = 1.0;
};

// Robust sigma of the per-pixel noise: horizontal differences of neighbours are noise times
// sqrt(2) plus the (small, sparse) image structure; their mean absolute value, trimmed so that
// edges and blobs do not count, gives sigma = E|d| / (sqrt(2) sqrt(2 / pi)).
double EstimateNoiseSigma(const cv::Mat& luma) {
  constexpr int kCap = 12;  // gray levels; larger differences are structure
  std::array<int64_t, kCap + 1> histogram{};
  for (int y = 1; y < luma.rows; y += 4) {
    const uint8_t* row = luma.ptr<uint8_t>(y);
    for (int x = 1; x < luma.cols; ++x) {
      const int d = std::abs(static_cast<int>(row[x]) - static_cast<int>(row[x - 1]));
      if (d <= kCap) ++histogram[d];
    }
  }
  int64_t count = 0;
  double sum = 0.0;
  for (int d = 0; d <= kCap; ++d) {
    count += histogram[d];
    sum += static_cast<double>(d) * histogram[d];
  }
  if (count == 0) return 0.0;
  return (sum / count) * std::sqrt(kPi) / 2.0;
}

// Union-find node of the flooding.
struct Region {
  int parent;
  int peak_level;
};

int FindRoot(std::vector<Region>& regions, int r) {
  while (regions[r].parent != r) {
    regions[r].parent = regions[regions[r].parent].parent;
    r = regions[r].parent;
  }
  return r;
}

struct Blob {
  std::vector<int> pixels;  // linear indices, brightest (smoothed) first
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // bounding box, inclusive
  double luma_contrast = 0.0;  // smoothed luma - background at the brightest pixel
  double luma_energy = 0.0;    // sum of luma - background, gray levels x pixels
  double peak = 0.0;           // raw luma maximum
  std::array<double, 3> channel_contrast{};  // raw maximum - background, per channel
  std::array<double, 3> channel_energy{};
  std::array<bool, 3> channel_saturated{};
  int channel = 0;             // channel the position is measured in
  double u = 0.0, v = 0.0;     // pixels
  double sigma = 0.0;          // Gaussian sigma, pixels
  double amplitude = 0.0;      // unclipped peak above background in `channel`, gray levels
  double elongation = 1.0;     // sqrt of the ratio of the principal second moments
  double red_ratio = 0.0;      // red excess / max(blue, green) excess
  double fit_rms = 0.0;        // weighted RMS residual of the fit / amplitude
  bool fitted = false;
  double fit_shift = 0.0;
  bool rejected = false;
  double score = 0.0;
};

// Splits the connected components of `mask` into blobs, one per significant local maximum of
// `smoothed`, by flooding: pixels are visited in descending level and join the neighbouring
// region with the highest peak; a region that rises less than min_prominence above the level at
// which it meets a brighter one is absorbed by it (a shoulder, e.g. a merged reflection, or a
// noise bump), otherwise it stays a separate blob. Linear time (counting sort on 8-bit levels).
std::vector<Blob> SegmentBlobs(const cv::Mat& smoothed, const cv::Mat& labels,
                               const cv::Mat& stats, int num_labels, int min_area, int max_area,
                               double min_prominence, std::vector<int>* region_of) {
  const int rows = smoothed.rows;
  const int cols = smoothed.cols;
  std::vector<Blob> blobs;
  std::vector<int> order;
  std::vector<Region> regions;
  std::vector<int> blob_of_root;
  for (int label = 1; label < num_labels; ++label) {
    const int area = stats.at<int>(label, cv::CC_STAT_AREA);
    if (area < min_area || area > max_area) continue;
    const int bx = stats.at<int>(label, cv::CC_STAT_LEFT);
    const int by = stats.at<int>(label, cv::CC_STAT_TOP);
    const int bw = stats.at<int>(label, cv::CC_STAT_WIDTH);
    const int bh = stats.at<int>(label, cv::CC_STAT_HEIGHT);

    std::array<int, 257> start{};
    for (int y = by; y < by + bh; ++y) {
      const int* l = labels.ptr<int>(y);
      const uint8_t* s = smoothed.ptr<uint8_t>(y);
      for (int x = bx; x < bx + bw; ++x) {
        if (l[x] == label) ++start[kFullScale - s[x] + 1];
      }
    }
    std::partial_sum(start.begin(), start.end(), start.begin());
    order.assign(area, 0);
    for (int y = by; y < by + bh; ++y) {
      const int* l = labels.ptr<int>(y);
      const uint8_t* s = smoothed.ptr<uint8_t>(y);
      for (int x = bx; x < bx + bw; ++x) {
        if (l[x] == label) order[start[kFullScale - s[x]]++] = y * cols + x;
      }
    }

    regions.clear();
    for (int index : order) {
      const int x = index % cols;
      const int y = index / cols;
      const int level = smoothed.ptr<uint8_t>(y)[x];
      std::array<int, 8> roots;
      int num_roots = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        const int yy = y + dy;
        if (yy < 0 || yy >= rows) continue;
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          if ((dx == 0 && dy == 0) || xx < 0 || xx >= cols) continue;
          const int r = (*region_of)[yy * cols + xx];
          // region_of is reset per component below, so r >= 0 means "this component, visited".
          if (r < 0) continue;
          const int root = FindRoot(regions, r);
          if (std::find(roots.begin(), roots.begin() + num_roots, root) ==
              roots.begin() + num_roots) {
            roots[num_roots++] = root;
          }
        }
      }
      if (num_roots == 0) {
        (*region_of)[index] = static_cast<int>(regions.size());
        regions.push_back({static_cast<int>(regions.size()), level});
        continue;
      }
      int winner = roots[0];
      for (int k = 1; k < num_roots; ++k) {
        if (regions[roots[k]].peak_level > regions[winner].peak_level) winner = roots[k];
      }
      for (int k = 0; k < num_roots; ++k) {
        const int r = roots[k];
        if (r != winner && regions[r].peak_level - level < min_prominence) {
          regions[r].parent = winner;
        }
      }
      (*region_of)[index] = winner;
    }

    blob_of_root.assign(regions.size(), -1);
    for (int index : order) {
      const int root = FindRoot(regions, (*region_of)[index]);
      if (blob_of_root[root] < 0) {
        blob_of_root[root] = static_cast<int>(blobs.size());
        blobs.emplace_back();
      }
      blobs[blob_of_root[root]].pixels.push_back(index);
    }
    for (int index : order) (*region_of)[index] = -1;
  }
  return blobs;
}

// Robust least-squares fit of an isotropic Gaussian on a local plane to one channel around a
// blob, optionally with a second, "reflection" Gaussian below it:
//   m(x, y) = bg(x, y) + b0 + bx (x - u0) + by (y - v0) + A g(x, y; u, v, s)
//             [+ A_r g(x, y; u_r, v_r, s_r)],   g = exp(-((x - u)^2 + (y - v)^2) / (2 s^2))
// bg is the coarse background. Clipped pixels (value 255) only say m >= 255: they have no
// residual when the model agrees. Residuals where the image is brighter than the model (other
// light added on top: a reflection, a neighbouring light, a particle) are down-weighted by a
// Cauchy loss; residuals where it is darker are plain least squares, since nothing in the scene
// subtracts light. Levenberg-Marquardt on (u, v, log s, A, b0, bx, by [, u_r, v_r, log s_r, A_r]).
struct FitResult {
  bool ok = false;
  double u = 0.0, v = 0.0, sigma = 0.0, amplitude = 0.0, rms = 0.0;
  double background = 0.0;  // fitted background level at (u, v)
  double reflection_u = 0.0, reflection_v = 0.0, reflection_sigma = 0.0, reflection_amplitude = 0.0;
};

struct FitSample {
  float x, y, value;
  bool clipped;
};

struct FitStart {
  double u, v, sigma, amplitude;
};

template <int kParams>
FitResult FitModel(const std::vector<FitSample>& samples, const FitStart& start, double noise,
                   double taper_sigmas) {
  static_assert(kParams == 10 || kParams == 14, "light, or light + reflection");
  constexpr bool kReflection = kParams == 14;
  constexpr int kR = 10;  // first reflection parameter
  using Vec = Eigen::Matrix<double, kParams, 1>;
  using Mat = Eigen::Matrix<double, kParams, kParams>;
  const double u0 = start.u, v0 = start.v;
  const double inv_s0 = 1.0 / std::max(0.5, start.sigma);
  Vec theta;
  theta.setZero();
  theta[0] = start.u;
  theta[1] = start.v;
  theta[2] = std::log(std::max(0.5, start.sigma));
  theta[3] = std::max(1.0, start.amplitude);
  {
    // Start the background offset at the median level of the window's outer samples.
    std::vector<float> outer;
    for (const FitSample& q : samples) {
      if (std::hypot(q.x - start.u, q.y - start.v) > 2.5 * start.sigma) outer.push_back(q.value);
    }
    if (!outer.empty()) {
      std::nth_element(outer.begin(), outer.begin() + outer.size() / 2, outer.end());
      theta[4] = outer[outer.size() / 2];
    }
  }
  if constexpr (kReflection) {
    // A reflection a few sigma below, wider and much dimmer; the fit moves it.
    theta[kR] = start.u;
    theta[kR + 1] = start.v + 3.0 * start.sigma + 3.0;
    theta[kR + 2] = std::log(1.6 * std::max(0.5, start.sigma));
    theta[kR + 3] = 0.15 * theta[3];
  }
  noise = std::max(0.5, noise);

  auto evaluate = [&](const Vec& p, Mat* jtj, Vec* jtr, double* weighted_sq) {
    const double u = p[0], v = p[1], s = std::exp(p[2]), a = p[3];
    const double inv_s2 = 1.0 / (s * s);
    double ur = 0.0, vr = 0.0, inv_sr2 = 0.0, ar = 0.0;
    if constexpr (kReflection) {
      ur = p[kR];
      vr = p[kR + 1];
      inv_sr2 = std::exp(-2.0 * p[kR + 2]);
      ar = p[kR + 3];
    }
    const double scale = std::max(3.0 * noise, 0.05 * std::abs(a));
    const double taper = taper_sigmas * s;
    double cost = 0.0, wsq = 0.0;
    if (jtj) jtj->setZero();
    if (jtr) jtr->setZero();
    Vec j;
    for (const FitSample& q : samples) {
      const double dx = q.x - u, dy = q.y - v;
      const double r2 = dx * dx + dy * dy;
      const double g = std::exp(-0.5 * r2 * inv_s2);
      const double qx = (q.x - u0) * inv_s0, qy = (q.y - v0) * inv_s0;
      double model = p[4] + p[5] * qx + p[6] * qy + p[7] * qx * qx + p[8] * qx * qy +
                     p[9] * qy * qy + a * g;
      double gr = 0.0, dxr = 0.0, dyr = 0.0, rr2 = 0.0;
      if constexpr (kReflection) {
        dxr = q.x - ur;
        dyr = q.y - vr;
        rr2 = dxr * dxr + dyr * dyr;
        gr = std::exp(-0.5 * rr2 * inv_sr2);
        model += ar * gr;
      }
      if (q.clipped && model >= kFullScale) continue;
      const double r = q.value - model;
      // Position weight: below the light (where its reflection lies) the data count less.
      double w = 1.0;
      if (taper > 0.0 && dy > 0.0) w = std::exp(-0.5 * (dy / taper) * (dy / taper));
      const double position_weight = w;
      if (r > 0.0) {
        const double z = r / scale;
        w *= 1.0 / (1.0 + z * z);
        cost += position_weight * 0.5 * scale * scale * std::log1p(z * z);
      } else {
        cost += position_weight * 0.5 * r * r;
      }
      wsq += w * r * r;
      if (!jtj) continue;
      const double ag = a * g * inv_s2;
      j[0] = ag * dx;
      j[1] = ag * dy;
      j[2] = ag * r2;
      j[3] = g;
      j[4] = 1.0;
      j[5] = qx;
      j[6] = qy;
      j[7] = qx * qx;
      j[8] = qx * qy;
      j[9] = qy * qy;
      if constexpr (kReflection) {
        const double agr = ar * gr * inv_sr2;
        j[kR] = agr * dxr;
        j[kR + 1] = agr * dyr;
        j[kR + 2] = agr * rr2;
        j[kR + 3] = gr;
      }
      jtj->template selfadjointView<Eigen::Lower>().rankUpdate(j, w);
      *jtr += (w * r) * j;
    }
    if (jtj) *jtj = jtj->template selfadjointView<Eigen::Lower>();
    if (weighted_sq) *weighted_sq = wsq;
    return cost;
  };

  Mat jtj;
  Vec jtr;
  double cost = evaluate(theta, &jtj, &jtr, nullptr);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 25; ++iteration) {
    Mat damped = jtj;
    damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-6);
    const Vec step = damped.ldlt().solve(jtr);
    if (!step.allFinite()) break;
    Vec candidate = theta + step;
    if constexpr (kReflection) candidate[kR + 3] = std::max(0.0, candidate[kR + 3]);
    const double candidate_cost = evaluate(candidate, nullptr, nullptr, nullptr);
    if (candidate_cost < cost) {
      theta = candidate;
      cost = evaluate(theta, &jtj, &jtr, nullptr);
      lambda = std::max(1e-7, lambda * 0.3);
      if (std::abs(step[0]) < 1e-3 && std::abs(step[1]) < 1e-3) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e6) break;
    }
  }
  double weighted_sq = 0.0;
  evaluate(theta, nullptr, nullptr, &weighted_sq);
  FitResult result;
  result.u = theta[0];
  result.v = theta[1];
  result.sigma = std::exp(theta[2]);
  result.amplitude = theta[3];
  result.rms = std::sqrt(weighted_sq / samples.size());
  {
    const double qx = (result.u - u0) * inv_s0, qy = (result.v - v0) * inv_s0;
    result.background = theta[4] + theta[5] * qx + theta[6] * qy + theta[7] * qx * qx +
                        theta[8] * qx * qy + theta[9] * qy * qy;
  }
  if constexpr (kReflection) {
    result.reflection_u = theta[kR];
    result.reflection_v = theta[kR + 1];
    result.reflection_sigma = std::exp(theta[kR + 2]);
    result.reflection_amplitude = theta[kR + 3];
  }
  result.ok = std::isfinite(result.u) && std::isfinite(result.v) && result.amplitude > 0.0 &&
              result.sigma > 0.3 && result.sigma < 4.0 * start.sigma + 5.0 &&
              std::hypot(result.u - start.u, result.v - start.v) < 2.0 * start.sigma + 2.0;
  return result;
}

// Pixels of one channel in [x0, x1] x [y0, y1], subsampled on a grid through (cx, cy) to at
// most about max_pixels.
std::vector<FitSample> CollectSamples(const cv::Mat& image, int channel, int cx, int cy, int x0,
                                      int x1, int y0, int y1, int max_pixels) {
  x0 = std::max(0, x0);
  y0 = std::max(0, y0);
  x1 = std::min(image.cols - 1, x1);
  y1 = std::min(image.rows - 1, y1);
  std::vector<FitSample> samples;
  if (x0 > x1 || y0 > y1) return samples;
  const double area = static_cast<double>(x1 - x0 + 1) * (y1 - y0 + 1);
  const int stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(area / max_pixels))));
  const int xs = cx - ((cx - x0) / stride) * stride;
  const int ys = cy - ((cy - y0) / stride) * stride;
  const int channels = image.channels();
  samples.reserve(static_cast<size_t>(area / (stride * stride)) + 4);
  for (int y = ys; y <= y1; y += stride) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = xs; x <= x1; x += stride) {
      const int value = row[channels * x + channel];
      samples.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(value),
                         value >= kFullScale});
    }
  }
  return samples;
}

FitResult FitLight(const cv::Mat& image, int channel, const FitStart& start, double noise, int max_pixels, double taper_sigmas,
                   bool model_reflection) {
  const int cx = static_cast<int>(std::lround(start.u));
  const int cy = static_cast<int>(std::lround(start.v));
  const int half = static_cast<int>(std::ceil(3.0 * start.sigma)) + 2;
  FitResult result;
  {
    const std::vector<FitSample> samples = CollectSamples(
        image, channel, cx, cy, cx - half, cx + half, cy - half, cy + half, max_pixels);
    if (samples.size() < 12) return result;
    result = FitModel<10>(samples, start, noise, taper_sigmas);
  }
  if (!model_reflection || !result.ok) return result;
  const FitStart refined{result.u, result.v, result.sigma, result.amplitude};
  const int below = static_cast<int>(std::ceil(3.0 * refined.sigma + 3.0 + 3.0 * 1.6 * refined.sigma));
  const int half2 = static_cast<int>(std::ceil(3.0 * refined.sigma)) + 2;
  const int cx2 = static_cast<int>(std::lround(refined.u));
  const int cy2 = static_cast<int>(std::lround(refined.v));
  const std::vector<FitSample> samples =
      CollectSamples(image, channel, cx2, cy2, cx2 - half2 - below / 2,
                     cx2 + half2 + below / 2, cy2 - half2, cy2 + below, max_pixels);
  if (samples.size() < 20) return result;
  const FitResult two_component = FitModel<14>(samples, refined, noise, 0.0);
  // The second component must be what it is meant to be: a dimmer blob below the light, not the
  // light itself (the fit can swap the two).
  const bool plausible = two_component.ok &&
                         two_component.reflection_amplitude < two_component.amplitude &&
                         two_component.reflection_v > two_component.v + 0.5 * two_component.sigma &&
                         std::hypot(two_component.u - result.u, two_component.v - result.v) <
                             0.5 * result.sigma + 1.0;
  return plausible ? two_component : result;
}

// Mean of one channel over the disc of radius max(1, sigma / 2) around (u, v).
double CentralMean(const cv::Mat& image, int channel, double u, double v, double sigma) {
  const double radius = std::max(1.0, 0.5 * sigma);
  const int channels = image.channels();
  double sum = 0.0;
  int count = 0;
  for (int y = std::max(0, static_cast<int>(std::floor(v - radius)));
       y <= std::min(image.rows - 1, static_cast<int>(std::ceil(v + radius))); ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = std::max(0, static_cast<int>(std::floor(u - radius)));
         x <= std::min(image.cols - 1, static_cast<int>(std::ceil(u + radius))); ++x) {
      if (std::hypot(x - u, y - v) > radius) continue;
      sum += row[channels * x + channel];
      ++count;
    }
  }
  return count > 0 ? sum / count : 0.0;
}

// Red excess over the larger of the blue and green excesses in the core of a small blob (radius
// 1.5 sigma, at least 1.5 px), against the per-channel median of a thin ring just outside it, so
// that a neighbouring light's tail under a particle cancels.
double CoreRedRatio(const cv::Mat& image, double u, double v, double sigma) {
  const double core = std::max(1.5, 1.5 * sigma);
  const double ring_in = core + 1.5, ring_out = core + 3.5;
  const int x0 = std::max(0, static_cast<int>(std::floor(u - ring_out)));
  const int x1 = std::min(image.cols - 1, static_cast<int>(std::ceil(u + ring_out)));
  const int y0 = std::max(0, static_cast<int>(std::floor(v - ring_out)));
  const int y1 = std::min(image.rows - 1, static_cast<int>(std::ceil(v + ring_out)));
  std::array<std::vector<int>, 3> ring;
  std::array<double, 3> sum{};
  int count = 0;
  for (int y = y0; y <= y1; ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = x0; x <= x1; ++x) {
      const double d = std::hypot(x - u, y - v);
      const uint8_t* pixel = row + 3 * x;
      if (d <= core) {
        for (int c = 0; c < 3; ++c) sum[c] += pixel[c];
        ++count;
      } else if (d >= ring_in && d <= ring_out) {
        for (int c = 0; c < 3; ++c) ring[c].push_back(pixel[c]);
      }
    }
  }
  if (count == 0 || ring[0].empty()) return 0.0;
  std::array<double, 3> excess{};
  for (int c = 0; c < 3; ++c) {
    std::vector<int>& r = ring[c];
    std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
    excess[c] = sum[c] - count * static_cast<double>(r[r.size() / 2]);
  }
  return excess[2] / std::max({1.0, excess[0], excess[1]});
}

}  // namespace

LightDetector::LightDetector(const LightDetectorOptions& options)
    : options_(options), dehazer_(options.dehaze_options) {}

std::vector<LightDetection> LightDetector::Detect(const cv::Mat& bgr8) const {
  if (bgr8.empty()) throw std::invalid_argument("LightDetector: empty image");
  if (bgr8.depth() != CV_8U || (bgr8.channels() != 1 && bgr8.channels() != 3)) {
    throw std::invalid_argument("LightDetector: image must be 8-bit BGR or gray");
  }
  static const bool debug = std::getenv("AUVDOCK_DETECTOR_DEBUG") != nullptr;
  const cv::Mat image = options_.dehaze ? dehazer_.Dehaze(bgr8).image : bgr8;
  const int rows = image.rows;
  const int cols = image.cols;
  const int channels = image.channels();

  cv::Mat luma;
  if (channels == 3) {
    cv::cvtColor(image, luma, cv::COLOR_BGR2GRAY);
  } else {
    luma = image;
  }
  cv::Mat smoothed = luma;
  if (options_.median_ksize >= 3) cv::medianBlur(smoothed, smoothed, options_.median_ksize | 1);
  if (options_.prefilter_sigma_px > 0.0) {
    cv::GaussianBlur(smoothed, smoothed, cv::Size(0, 0), options_.prefilter_sigma_px);
  }

  const double noise = EstimateNoiseSigma(luma);
  const double sf = std::max(0.0, options_.prefilter_sigma_px);
  // A Gaussian pre-filter of sigma s averages about 4 pi s^2 pixels of white noise.
  const double smoothed_noise = sf > 0.0 ? noise / (2.0 * std::sqrt(kPi) * std::max(0.5, sf)) : noise;
  const double threshold =
      std::max(options_.min_contrast, options_.threshold_noise_sigmas * smoothed_noise);

  const CoarseBackground luma_background(smoothed, options_.background_grid_cols,
                                         options_.background_window_cells);
  const CoarseBackground colour_background(image, options_.background_grid_cols,
                                           options_.colour_background_window_cells);
  cv::Mat level;  // background + threshold, full resolution
  cv::resize(luma_background.plane(0) + threshold, level, smoothed.size(), 0, 0, cv::INTER_LINEAR);
  level.convertTo(level, CV_8U);
  cv::Mat mask;
  cv::compare(smoothed, level, mask, cv::CMP_GT);

  cv::Mat labels, stats, centroids;
  const int num_labels = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  std::vector<int> region_of(static_cast<size_t>(rows) * cols, -1);
  const int max_area = static_cast<int>(options_.max_area_fraction * rows * cols);
  std::vector<Blob> blobs = SegmentBlobs(smoothed, labels, stats, num_labels, options_.min_area_px,
                                         max_area, options_.min_prominence, &region_of);

  // Measurements: contrast and energy in luma and per channel, the channel to measure the
  // position in, a first centroid and second moments.
  for (Blob& blob : blobs) {
    blob.x0 = cols;
    blob.y0 = rows;
    blob.x1 = blob.y1 = -1;
    std::array<double, 3> peak_value{};
    std::array<int, 3> peak_index{};
    std::array<int, 3> saturated_count{};
    for (int index : blob.pixels) {
      const int x = index % cols;
      const int y = index / cols;
      blob.x0 = std::min(blob.x0, x);
      blob.x1 = std::max(blob.x1, x);
      blob.y0 = std::min(blob.y0, y);
      blob.y1 = std::max(blob.y1, y);
      const double l = luma.ptr<uint8_t>(y)[x];
      blob.peak = std::max(blob.peak, l);
      blob.luma_energy += l - luma_background.At(0, x, y);
      const uint8_t* pixel = image.ptr<uint8_t>(y) + channels * x;
      for (int c = 0; c < channels; ++c) {
        const double value = pixel[c];
        blob.channel_energy[c] += value - colour_background.At(c, x, y);
        saturated_count[c] += value >= kSaturatedLevel;
        if (value > peak_value[c]) {
          peak_value[c] = value;
          peak_index[c] = index;
        }
      }
    }
    {
      const int index = blob.pixels.front();  // brightest smoothed pixel
      const int x = index % cols, y = index / cols;
      blob.luma_contrast = smoothed.ptr<uint8_t>(y)[x] - luma_background.At(0, x, y);
    }
    // A channel counts as clipped when a few percent of the blob is at full scale (one particle on
    // the blob clips a handful of pixels, and must not decide).
    const int clipped_pixels =
        std::max(3, static_cast<int>(0.02 * static_cast<double>(blob.pixels.size())));
    double best_contrast = 0.0;
    int best_any = 0;
    for (int c = 0; c < channels; ++c) {
      const int index = peak_index[c];
      blob.channel_contrast[c] =
          peak_value[c] - colour_background.At(c, index % cols, index / cols);
      blob.channel_saturated[c] = saturated_count[c] >= clipped_pixels;
      best_contrast = std::max(best_contrast, blob.channel_contrast[c]);
      if (blob.channel_energy[c] > blob.channel_energy[best_any]) best_any = c;
    }
    // The position is measured in the unclipped channel with the most light (energy, which a
    // small particle on the blob hardly changes), unless it is much weaker than a clipped one
    // (then the clipped channel's edges carry more information).
    int best_unclipped = -1;
    for (int c = 0; c < channels; ++c) {
      if (blob.channel_saturated[c]) continue;
      if (best_unclipped < 0 || blob.channel_energy[c] > blob.channel_energy[best_unclipped]) {
        best_unclipped = c;
      }
    }
    if (best_unclipped >= 0 && blob.channel_contrast[best_unclipped] >=
                                   std::min(options_.min_fit_contrast, 0.25 * best_contrast)) {
      blob.channel = best_unclipped;
    } else {
      // Every usable channel is clipped: take the one with the smallest clipped core, which is
      // the light's own (a reflection or a neighbour merges into a larger plateau).
      blob.channel = best_any;
      for (int c = 0; c < channels; ++c) {
        if (blob.channel_contrast[c] < std::min(options_.min_fit_contrast, 0.25 * best_contrast)) {
          continue;
        }
        if (saturated_count[c] < saturated_count[blob.channel]) blob.channel = c;
      }
    }
    if (channels == 3) {
      blob.red_ratio = blob.channel_energy[2] /
                       std::max({1.0, blob.channel_energy[0], blob.channel_energy[1]});
    }

    // First estimate: centroid of the channel above half its peak, and the blob's sigma from its
    // energy (a Gaussian of peak P and sigma s holds 2 pi s^2 P).
    const int c = blob.channel;
    const double half_level = 0.5 * blob.channel_contrast[c];
    double sw = 0.0, su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
    for (int index : blob.pixels) {
      const int x = index % cols, y = index / cols;
      const double w = image.ptr<uint8_t>(y)[channels * x + c] - colour_background.At(c, x, y) -
                       half_level;
      if (w <= 0.0) continue;
      sw += w;
      su += w * x;
      sv += w * y;
      suu += w * x * x;
      svv += w * y * y;
      suv += w * x * y;
    }
    if (sw <= 0.0) {
      blob.rejected = true;
      continue;
    }
    blob.u = su / sw;
    blob.v = sv / sw;
    const double cuu = suu / sw - blob.u * blob.u;
    const double cvv = svv / sw - blob.v * blob.v;
    const double cuv = suv / sw - blob.u * blob.v;
    const double mean = 0.5 * (cuu + cvv);
    const double spread = std::sqrt(0.25 * (cuu - cvv) * (cuu - cvv) + cuv * cuv);
    blob.elongation = std::sqrt((mean + spread) / std::max(1e-6, mean - spread));
    const double contrast_c = std::max(1.0, blob.channel_contrast[c]);
    blob.sigma = std::sqrt(std::max(0.25, blob.channel_energy[c] / (2.0 * kPi * contrast_c)));
    blob.amplitude = contrast_c;
  }

  for (Blob& blob : blobs) {
    if (blob.rejected) continue;
    // A blob cut by the image border looks elongated (a half disc: 1.9) whatever it is.
    const bool at_border = blob.x0 <= 0 || blob.y0 <= 0 || blob.x1 >= cols - 1 || blob.y1 >= rows - 1;
    if (blob.luma_contrast < options_.min_peak_contrast ||
        static_cast<int>(blob.pixels.size()) < options_.min_area_px ||
        blob.elongation > (at_border ? 1.6 : 1.0) * options_.max_elongation) {
      if (debug) std::printf("    reject %.1f,%.1f lc %.1f area %zu el %.2f\n", blob.u, blob.v, blob.luma_contrast, blob.pixels.size(), blob.elongation);
      blob.rejected = true;
      continue;
    }
    if (options_.reject_particles && blob.sigma <= options_.particle_max_sigma_px &&
        (channels == 1 || blob.red_ratio >= options_.particle_min_red_ratio)) {
      if (debug) {
        std::printf("    particle at %.1f,%.1f sigma %.2f red %.2f\n", blob.u, blob.v, blob.sigma,
                    blob.red_ratio);
      }
      blob.rejected = true;
    }
  }

  for (Blob& blob : blobs) {
    if (blob.rejected) continue;
    const FitResult fit = FitLight(image, blob.channel, {blob.u, blob.v, blob.sigma, blob.amplitude}, noise,
                                   options_.max_fit_pixels, options_.fit_taper_sigmas,
                                   options_.model_reflections);
    if (debug) {
      std::printf("    fit ch %d: %.2f,%.2f s %.2f A %.1f -> ok %d %.2f,%.2f s %.2f A %.1f rms %.2f refl %.2f,%.2f s %.2f A %.1f\n",
                  blob.channel, blob.u, blob.v, blob.sigma, blob.amplitude, fit.ok, fit.u, fit.v,
                  fit.sigma, fit.amplitude, fit.rms, fit.reflection_u, fit.reflection_v, fit.reflection_sigma, fit.reflection_amplitude);
    }
    if (!fit.ok) {
      blob.rejected = true;
      continue;
    }
    blob.fitted = true;
    blob.fit_shift = std::hypot(fit.u - blob.u, fit.v - blob.v) / std::max(0.5, fit.sigma);
    blob.u = fit.u;
    blob.v = fit.v;
    blob.sigma = fit.sigma;
    blob.amplitude = fit.amplitude;
    blob.fit_rms = fit.rms;
    double max_contrast = 0.0;
    for (int c = 0; c < channels; ++c) max_contrast = std::max(max_contrast, blob.channel_contrast[c]);
    // The model must explain the blob's centre: a fit that drifted onto a tiny bump beside a
    // bright plateau (the lamp's hot spot, a white-out) leaves most of the centre unexplained.
    const double central = CentralMean(image, blob.channel, fit.u, fit.v, fit.sigma) - fit.background;
    const double explained = std::min(0.94 * fit.amplitude, kFullScale - fit.background);
    // Size against brightness: a light that looks big is near, and a near light is bright, so an
    // unclipped blob must rise by a minimum per pixel of sigma (per 640 pixels of image width, as
    // sigma scales with the focal length); a clipped one has run out of headroom instead.
    const bool clipped = blob.channel_saturated[0] || blob.channel_saturated[1] || blob.channel_saturated[2];
    const double size = blob.sigma * 640.0 / cols;
    const double min_contrast = (clipped ? options_.min_clipped_contrast_per_sigma
                                         : options_.min_contrast_per_sigma) * size;
    if (central > 2.0 * explained + 3.0 * noise || blob.fit_shift > options_.max_fit_shift_sigmas ||
        blob.sigma < options_.min_sigma_px || max_contrast < min_contrast) {
      if (debug) std::printf("    inconsistent fit at %.1f,%.1f sigma %.2f A %.1f central %.1f maxc %.1f\n", blob.u, blob.v, blob.sigma, blob.amplitude, central, max_contrast);
      blob.rejected = true;
      continue;
    }
    if (options_.reject_particles && blob.sigma <= options_.particle_max_sigma_px) {
      if (channels == 3) blob.red_ratio = CoreRedRatio(image, blob.u, blob.v, blob.sigma);
      if (channels == 1 || blob.red_ratio >= options_.particle_min_red_ratio) {
        if (debug) std::printf("    particle after fit at %.1f,%.1f sigma %.2f red %.2f\n", blob.u, blob.v, blob.sigma, blob.red_ratio);
        blob.rejected = true;
      }
    }
  }

  // Reflections: a dimmer blob just below a brighter one, as far below as the reflection's
  // geometry allows (a few source sigmas).
  if (options_.reject_reflections) {
    std::vector<int> by_brightness(blobs.size());
    std::iota(by_brightness.begin(), by_brightness.end(), 0);
    std::sort(by_brightness.begin(), by_brightness.end(),
              [&](int a, int b) { return blobs[a].luma_energy > blobs[b].luma_energy; });
    for (int j : by_brightness) {
      const Blob& source = blobs[j];
      if (source.rejected) continue;
      const double s = std::max(0.8, source.sigma);
      for (Blob& candidate : blobs) {
        if (candidate.rejected || &candidate == &source) continue;
        const double dv = candidate.v - source.v;
        const double du = std::abs(candidate.u - source.u);
        if (dv < options_.reflection_min_offset_sigmas * s ||
            dv > options_.reflection_max_offset_sigmas * s + options_.reflection_max_offset_px ||
            du > options_.reflection_max_lateral_sigmas * s + 2.0) {
          continue;
        }
        // Dimmer: compared in the source's measuring channel (unclipped there when possible).
        const int c = source.channel;
        const bool dimmer =
            source.channel_saturated[c]
                ? candidate.luma_energy < options_.reflection_max_ratio * source.luma_energy
                : candidate.channel_contrast[c] <
                      options_.reflection_max_ratio * source.channel_contrast[c];
        if (debug) {
          std::printf("    pair src %.1f,%.1f s=%.2f | cand %.1f,%.1f s=%.2f dv/s=%.2f du/s=%.2f "
                      "ratio c %.2f E %.2f -> %d\n",
                      source.u, source.v, source.sigma, candidate.u, candidate.v, candidate.sigma,
                      dv / s, du / s, candidate.channel_contrast[c] / source.channel_contrast[c],
                      candidate.luma_energy / source.luma_energy, dimmer);
        }
        if (dimmer) candidate.rejected = true;
      }
    }
  }

  std::vector<LightDetection> detections;
  for (const Blob& blob : blobs) {
    if (blob.rejected) continue;
    LightDetection d;
    d.uv = Eigen::Vector2d(blob.u, blob.v);
    d.radius_px = std::sqrt(blob.pixels.size() / kPi);
    d.peak = blob.peak;
    d.score = std::min(1.0, blob.luma_contrast / 255.0);
    static const bool feat = std::getenv("AUVDOCK_FEAT") != nullptr;
    if (feat) {
      double maxc = 0; for (int c = 0; c < channels; ++c) maxc = std::max(maxc, blob.channel_contrast[c]);
      const bool at_border = blob.x0 <= 0 || blob.y0 <= 0 || blob.x1 >= cols - 1 || blob.y1 >= rows - 1;
      const double expected_area = kPi * 2.0 * blob.sigma * blob.sigma * std::log(std::max(1.5, blob.luma_contrast / threshold));
      std::printf("FEAT %.3f %.3f sigma %.2f A %.1f maxc %.1f lc %.1f el %.2f border %d rms %.2f noise %.2f red %.2f ch %d area %zu arearatio %.2f shift %.2f Acc %.2f sat %d\n",
                  blob.u, blob.v, blob.sigma, blob.amplitude, maxc, blob.luma_contrast, blob.elongation, at_border, blob.fit_rms, noise, blob.red_ratio, blob.channel, blob.pixels.size(),
                  blob.pixels.size() / expected_area, blob.fit_shift, blob.amplitude / std::max(1.0, blob.channel_contrast[blob.channel]), (int)(blob.channel_saturated[0] || blob.channel_saturated[1] || blob.channel_saturated[2]));
    }
    if (debug) {
      std::printf("    det %.2f,%.2f ch %d sigma %.2f A %.1f lc %.1f E %.0f el %.2f red %.2f fit %d\n",
                  blob.u, blob.v, blob.channel, blob.sigma, blob.amplitude, blob.luma_contrast,
                  blob.luma_energy, blob.elongation, blob.red_ratio, blob.fitted);
    }
    detections.push_back(d);
  }
  std::sort(detections.begin(), detections.end(),
            [](const LightDetection& a, const LightDetection& b) { return a.score > b.score; });
  return detections;
}

}  // namespace auvdock
