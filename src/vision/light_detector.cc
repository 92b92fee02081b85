#include "auvdock/vision/light_detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;
// A channel whose maximum in a blob reaches this is clipped there (the sensor's full scale).
constexpr int kSaturatedLevel = 250;
constexpr int kFullScale = 255;

// Per-channel background on a coarse grid: block means, a grey closing that fills dark structures
// narrower than close_cells (the lights' dark housings), then a grey opening (erosion followed by
// dilation) that removes every bright structure narrower than the window, then a 3 x 3 mean.
// Sampled bilinearly at full-resolution pixel centres.
class CoarseBackground {
 public:
  CoarseBackground(const cv::Mat& image, int grid_cols, int close_cells, int window_cells) {
    cols_ = std::max(2, std::min(grid_cols, image.cols));
    cell_x_ = static_cast<double>(image.cols) / cols_;
    rows_ = std::max(2, static_cast<int>(std::lround(image.rows / cell_x_)));
    rows_ = std::min(rows_, image.rows);
    cell_y_ = static_cast<double>(image.rows) / rows_;
    cv::Mat coarse;
    cv::resize(image, coarse, cv::Size(cols_, rows_), 0, 0, cv::INTER_AREA);
    coarse.convertTo(coarse, CV_32F);
    const int w = std::max(1, window_cells);
    const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(w, w));
    if (close_cells > 1) {
      cv::morphologyEx(
          coarse, coarse, cv::MORPH_CLOSE,
          cv::getStructuringElement(cv::MORPH_RECT, cv::Size(close_cells, close_cells)));
    }
    cv::morphologyEx(coarse, coarse, cv::MORPH_OPEN, square);
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

// Robust sigma of the per-pixel noise in one channel: differences of horizontal neighbours are
// noise times sqrt(2) plus the (small, sparse) image structure; their mean absolute value, with
// differences above a cap left out as structure, gives sigma = E|d| / (sqrt(2) sqrt(2 / pi)).
// Every eighth row is enough.
double EstimateNoiseSigma(const cv::Mat& image, int channel) {
  constexpr int kCap = 12;  // gray levels
  const int channels = image.channels();
  std::array<int64_t, kCap + 1> histogram{};
  for (int y = 1; y < image.rows; y += 8) {
    const uint8_t* row = image.ptr<uint8_t>(y) + channel;
    for (int x = 1; x < image.cols; ++x) {
      const int d = std::abs(static_cast<int>(row[channels * x]) -
                             static_cast<int>(row[channels * (x - 1)]));
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

// Pixel coordinates packed into one word, x in the low and y in the high 16 bits (Detect
// refuses larger images): pixel lists then need no division to recover a coordinate.
inline uint32_t Pack(int x, int y) {
  return (static_cast<uint32_t>(y) << 16) | static_cast<uint32_t>(x);
}
inline int PackedX(uint32_t p) { return static_cast<int>(p & 0xFFFFu); }
inline int PackedY(uint32_t p) { return static_cast<int>(p >> 16); }

// A blob before the fit: its pixels and first measurements.
struct Blob {
  std::vector<uint32_t> pixels;  // packed coordinates at the blob's scale, brightest first
  int scale = 1;            // pixels are on a grid downsampled by this factor
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // bounding box at full resolution, inclusive
  bool at_border = false;
  double luma_contrast = 0.0;  // smoothed luma - background at the brightest pixel
  double luma_energy = 0.0;    // sum of smoothed luma - background, gray levels x pixels
  double peak = 0.0;           // raw maximum over the blob and its channels, 0-255
  double area = 0.0;           // full-resolution pixels above the threshold
  std::array<double, 3> channel_contrast{};  // raw maximum - background, per channel
  std::array<bool, 3> channel_saturated{};   // more than a couple of pixels at full scale
  std::array<double, 3> background{};        // local background per channel
  int channel = 0;             // channel the position is measured in
  double u = 0.0, v = 0.0;     // centroid above half the peak in `channel`, pixels
  double sigma = 0.0;          // Gaussian sigma from the area above half the peak, pixels
  double amplitude = 0.0;      // peak above background in `channel`
  double elongation = 1.0;     // sqrt of the ratio of the principal second moments
  double red_ratio = 0.0;      // red excess / max(blue, green) excess
};

// Splits connected components into blobs, one per significant local maximum of `smoothed`, by
// flooding: pixels are visited in descending level and join the neighbouring region with the
// highest peak; a region that rises less than min_prominence above the level at which it meets a
// brighter one is absorbed by it (a shoulder, e.g. a merged reflection, or a noise bump),
// otherwise it stays a separate blob. Linear time (counting sort on 8-bit levels).
void SplitComponent(const cv::Mat& smoothed, const std::vector<uint32_t>& component, int bx,
                    int by, int bw, int bh, double min_prominence, std::vector<Blob>* blobs) {
  // The component's levels, in its own order, then a stable counting sort by descending level.
  std::vector<uint8_t> levels(component.size());
  for (size_t i = 0; i < component.size(); ++i) {
    levels[i] = smoothed.ptr<uint8_t>(PackedY(component[i]))[PackedX(component[i])];
  }
  std::array<int, kFullScale + 2> start{};
  for (uint8_t level : levels) ++start[kFullScale - level + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<uint32_t> order(component.size());
  std::vector<uint8_t> order_level(component.size());
  for (size_t i = 0; i < component.size(); ++i) {
    const int k = start[kFullScale - levels[i]]++;
    order[k] = component[i];
    order_level[k] = levels[i];
  }

  // Region ids on the bounding box with a one-pixel border, -1 where not visited (yet): only this
  // component's pixels are ever visited, so an id >= 0 means "same component".
  const int pw = bw + 2;
  std::vector<int> region_of(static_cast<size_t>(pw) * (bh + 2), -1);
  std::vector<Region> regions;
  for (size_t i = 0; i < order.size(); ++i) {
    const int x = PackedX(order[i]) - bx + 1;
    const int y = PackedY(order[i]) - by + 1;
    const int level = order_level[i];
    int& mine = region_of[y * pw + x];
    const int* c = &mine;
    const std::array<int, 8> neighbours{c[-pw - 1], c[-pw], c[-pw + 1], c[-1],
                                        c[1],       c[pw - 1], c[pw], c[pw + 1]};
    // Most pixels have no visited neighbour or neighbours of a single region: decided without
    // branching on each neighbour (as unsigned, -1 is the largest value).
    int highest = -1;
    uint32_t lowest = 0xFFFFFFFFu;
    for (int r : neighbours) {
      highest = std::max(highest, r);
      lowest = std::min(lowest, static_cast<uint32_t>(r));
    }
    if (highest < 0) {
      mine = static_cast<int>(regions.size());
      regions.push_back({static_cast<int>(regions.size()), level});
      continue;
    }
    if (static_cast<int>(lowest) == highest) {
      mine = FindRoot(regions, highest);
      continue;
    }
    // Several regions meet here: the distinct roots, in neighbour order.
    std::array<int, 8> roots;
    int num_roots = 0;
    for (int r : neighbours) {
      if (r < 0) continue;
      const int root = FindRoot(regions, r);
      if (std::find(roots.begin(), roots.begin() + num_roots, root) ==
          roots.begin() + num_roots) {
        roots[num_roots++] = root;
      }
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
    mine = winner;
  }

  std::vector<int> root_of(regions.size());
  for (size_t r = 0; r < regions.size(); ++r) root_of[r] = FindRoot(regions, static_cast<int>(r));
  std::vector<int> blob_of_root(regions.size(), -1);
  for (uint32_t p : order) {
    const int root = root_of[region_of[(PackedY(p) - by + 1) * pw + PackedX(p) - bx + 1]];
    if (blob_of_root[root] < 0) {
      blob_of_root[root] = static_cast<int>(blobs->size());
      blobs->emplace_back();
    }
    (*blobs)[blob_of_root[root]].pixels.push_back(p);
  }
}

// Robust least-squares fit of an isotropic Gaussian on a local quadratic background to one
// channel around a blob, optionally with a second, "reflection" Gaussian below it:
//   m(x, y) = q(x, y) + A g(x, y; u, v, s) [+ A_r g(x, y; u_r, v_r, s_r)],
//   g = exp(-((x - u)^2 + (y - v)^2) / (2 s^2)),  q a quadratic in (x - u0, y - v0) / s0.
// Clipped pixels (value 255) only say m >= 255: they have no residual when the model agrees.
// Residuals where the image is brighter than the model (other light added on top: a reflection,
// a neighbouring light, a particle) are down-weighted by a Geman-McClure loss of scale
// max(3 noise, A / 20); residuals where it is darker are plain least squares, since nothing in the
// scene subtracts light. Without the reflection term, samples below the light (where its
// reflection lies) can be down-weighted by a Gaussian taper of taper_sigmas * s. Levenberg-
// Marquardt on (u, v, log s, A, 6 background coefficients [, u_r, v_r, log s_r, A_r]), the
// reflection kept below the light, wider and dimmer by projection after each step.
struct FitResult {
  bool ok = false;
  double u = 0.0, v = 0.0, sigma = 0.0, amplitude = 0.0, rms = 0.0;
  double background = 0.0;  // fitted background level at (u, v)
  double reflection_u = 0.0, reflection_v = 0.0, reflection_sigma = 0.0, reflection_amplitude = 0.0;
};

// The samples of a fit, structure of arrays padded to a multiple of kFitLanes (padding: valid 0)
// so that the model is evaluated four samples at a time. Coordinates are relative to an integer
// origin near the light, so that in float they and the model's centre keep ~1e-5 px precision.
constexpr int kFitLanes = 4;
struct FitSamples {
  int count = 0;       // real samples
  int ox = 0, oy = 0;  // full-resolution pixel coordinates of the origin
  std::vector<float> x, y, value, valid;  // padded; value is the raw pixel (255: clipped)
};

struct FitStart {
  double u, v, sigma, amplitude;
};

// exp(x) in float for x <= 0 (Cephes' expf polynomial; ~2 ulp), exactly 1 at 0: the fit's
// Gaussians and taper, four at a time.
inline float FastExp(float x) {
  x = std::max(x, -87.0f);
  const float n = std::nearbyint(x * 1.44269504088896341f);
  const float r = x - n * 0.693359375f + n * 2.12194440e-4f;
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  const float y = p * r * r + r + 1.0f;
  const int32_t bits = (static_cast<int32_t>(n) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof(scale));
  return y * scale;
}

#if CV_SIMD128
inline cv::v_float32x4 FastExp(cv::v_float32x4 x) {
  x = cv::v_max(x, cv::v_setall_f32(-87.0f));
  const cv::v_int32x4 ni = cv::v_round(x * cv::v_setall_f32(1.44269504088896341f));
  const cv::v_float32x4 n = cv::v_cvt_f32(ni);
  const cv::v_float32x4 r =
      x - n * cv::v_setall_f32(0.693359375f) + n * cv::v_setall_f32(2.12194440e-4f);
  cv::v_float32x4 p = cv::v_setall_f32(1.9875691500e-4f);
  p = cv::v_muladd(p, r, cv::v_setall_f32(1.3981999507e-3f));
  p = cv::v_muladd(p, r, cv::v_setall_f32(8.3334519073e-3f));
  p = cv::v_muladd(p, r, cv::v_setall_f32(4.1665795894e-2f));
  p = cv::v_muladd(p, r, cv::v_setall_f32(1.6666665459e-1f));
  p = cv::v_muladd(p, r, cv::v_setall_f32(5.0000001201e-1f));
  const cv::v_float32x4 y = p * r * r + r + cv::v_setall_f32(1.0f);
  const cv::v_int32x4 bits = cv::v_shl<23>(ni + cv::v_setall_s32(127));
  return y * cv::v_reinterpret_as_f32(bits);
}
#endif

template <int kParams>
FitResult FitModel(const FitSamples& samples, const FitStart& start, double noise,
                   double taper_sigmas, int max_iterations) {
  static_assert(kParams == 10 || kParams == 14, "light, or light + reflection");
  constexpr bool kReflection = kParams == 14;
  constexpr int kR = 10;  // first reflection parameter
  using Vec = Eigen::Matrix<double, kParams, 1>;
  using Mat = Eigen::Matrix<double, kParams, kParams>;
  const double u0 = start.u, v0 = start.v;
  const double inv_s0 = 1.0 / std::max(0.5, start.sigma);
  const int num_samples = samples.count;
  const int padded = static_cast<int>(samples.x.size());
  Vec theta;
  theta.setZero();
  theta[0] = start.u;
  theta[1] = start.v;
  theta[2] = std::log(std::max(0.5, start.sigma));
  theta[3] = std::max(1.0, start.amplitude);
  {
    // Start the background offset at the median level of the window's outer samples.
    std::vector<float> outer;
    const double ru = start.u - samples.ox, rv = start.v - samples.oy;
    const double outer_radius2 = (2.5 * start.sigma) * (2.5 * start.sigma);
    for (int i = 0; i < num_samples; ++i) {
      const double dx = samples.x[i] - ru, dy = samples.y[i] - rv;
      if (dx * dx + dy * dy > outer_radius2) {
        outer.push_back(samples.value[i]);
      }
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

  // The background's basis (x - u0, y - v0) / s0 and its products, fixed during the fit.
  std::array<std::vector<float>, 5> basis;
  for (std::vector<float>& b : basis) b.resize(padded);
  for (int i = 0; i < padded; ++i) {
    const double qx = (samples.x[i] + (samples.ox - u0)) * inv_s0;
    const double qy = (samples.y[i] + (samples.oy - v0)) * inv_s0;
    basis[0][i] = static_cast<float>(qx);
    basis[1][i] = static_cast<float>(qy);
    basis[2][i] = static_cast<float>(qx * qx);
    basis[3][i] = static_cast<float>(qx * qy);
    basis[4][i] = static_cast<float>(qy * qy);
  }

  // The weighted Jacobian columns sqrt(w_i) J_i and residuals sqrt(w_i) r_i of all samples, in
  // float: the normal equations are then one symmetric rank-k update (vectorised by Eigen).
  // The model, its Jacobian and the weights are evaluated in float too, four samples at a time
  // with a polynomial exp: float's ~1e-7 relative error moves the converged centre by ~1e-6 px.
  Eigen::Matrix<float, Eigen::Dynamic, kParams> weighted_j(padded, kParams);
  Eigen::VectorXf weighted_r(padded);
  // Fills the weighted columns and residuals; returns the robust cost and the weighted squared
  // residual sum.
  auto evaluate = [&](const Vec& p, double* sum_sq) {
    const double s = std::exp(p[2]);
    const float u = static_cast<float>(p[0] - samples.ox);
    const float v = static_cast<float>(p[1] - samples.oy);
    const float a = static_cast<float>(p[3]);
    const float inv_s2 = static_cast<float>(1.0 / (s * s));
    const float gauss = -0.5f * inv_s2;
    std::array<float, 6> b;
    for (int k = 0; k < 6; ++k) b[k] = static_cast<float>(p[4 + k]);
    float ur = 0.0f, vr = 0.0f, inv_sr2 = 0.0f, ar = 0.0f;
    if constexpr (kReflection) {
      ur = static_cast<float>(p[kR] - samples.ox);
      vr = static_cast<float>(p[kR + 1] - samples.oy);
      inv_sr2 = static_cast<float>(std::exp(-2.0 * p[kR + 2]));
      ar = static_cast<float>(p[kR + 3]);
    }
    const float gauss_r = -0.5f * inv_sr2;
    const double scale = std::max(3.0 * noise, 0.05 * std::abs(p[3]));
    const float inv_scale = static_cast<float>(1.0 / scale);
    const float half_scale2 = static_cast<float>(0.5 * scale * scale);
    const double taper = taper_sigmas * s;
    const bool tapered = taper > 0.0;
    const float taper_k = tapered ? static_cast<float>(-0.25 / (taper * taper)) : 0.0f;
    std::array<float*, kParams> j;
    for (int k = 0; k < kParams; ++k) j[k] = weighted_j.col(k).data();
    float* wr_out = weighted_r.data();
    const float* xs = samples.x.data();
    const float* ys = samples.y.data();
    const float* values = samples.value.data();
    const float* valid = samples.valid.data();
    double cost = 0.0, wsq = 0.0;
#if CV_SIMD128
    using cv::v_float32x4;
    const v_float32x4 u4 = cv::v_setall_f32(u), v4 = cv::v_setall_f32(v);
    const v_float32x4 a4 = cv::v_setall_f32(a), gauss4 = cv::v_setall_f32(gauss);
    const v_float32x4 inv_s2_4 = cv::v_setall_f32(inv_s2);
    const v_float32x4 zero = cv::v_setzero_f32(), one = cv::v_setall_f32(1.0f);
    const v_float32x4 half = cv::v_setall_f32(0.5f), full = cv::v_setall_f32(kFullScale);
    const v_float32x4 inv_scale4 = cv::v_setall_f32(inv_scale);
    const v_float32x4 half_scale2_4 = cv::v_setall_f32(half_scale2);
    const v_float32x4 taper4 = cv::v_setall_f32(taper_k);
    std::array<v_float32x4, 6> b4;
    for (int k = 0; k < 6; ++k) b4[k] = cv::v_setall_f32(b[k]);
    const v_float32x4 ur4 = cv::v_setall_f32(ur), vr4 = cv::v_setall_f32(vr);
    const v_float32x4 ar4 = cv::v_setall_f32(ar), gauss_r4 = cv::v_setall_f32(gauss_r);
    const v_float32x4 inv_sr2_4 = cv::v_setall_f32(inv_sr2);
    cv::v_float64x2 cost2 = cv::v_setzero_f64(), wsq2 = cv::v_setzero_f64();
    for (int i = 0; i < padded; i += kFitLanes) {
      const v_float32x4 dx = cv::v_load(xs + i) - u4, dy = cv::v_load(ys + i) - v4;
      const v_float32x4 r2 = dx * dx + dy * dy;
      const v_float32x4 g = FastExp(r2 * gauss4);
      const v_float32x4 qx = cv::v_load(basis[0].data() + i), qy = cv::v_load(basis[1].data() + i);
      const v_float32x4 qxx = cv::v_load(basis[2].data() + i);
      const v_float32x4 qxy = cv::v_load(basis[3].data() + i);
      const v_float32x4 qyy = cv::v_load(basis[4].data() + i);
      v_float32x4 model = b4[0] + b4[1] * qx + b4[2] * qy + b4[3] * qxx + b4[4] * qxy +
                          b4[5] * qyy + a4 * g;
      v_float32x4 dxr = zero, dyr = zero, rr2 = zero, gr = zero;
      if constexpr (kReflection) {
        dxr = cv::v_load(xs + i) - ur4;
        dyr = cv::v_load(ys + i) - vr4;
        rr2 = dxr * dxr + dyr * dyr;
        gr = FastExp(rr2 * gauss_r4);
        model = model + ar4 * gr;
      }
      const v_float32x4 value = cv::v_load(values + i);
      // Position weight: below the light (where its reflection lies) the data count less.
      v_float32x4 sqrt_pw = cv::v_load(valid + i);
      if (tapered) {
        const v_float32x4 below = cv::v_max(dy, zero);
        sqrt_pw = sqrt_pw * FastExp(below * below * taper4);
      }
      // A clipped sample the model reaches has no residual.
      sqrt_pw = cv::v_select((value >= full) & (model >= full), zero, sqrt_pw);
      const v_float32x4 r = value - model;
      // Geman-McClure above the model: rho = s^2 z^2 / (2 (1 + z^2)), IRLS weight
      // 1 / (1 + z^2)^2; plain least squares below it.
      const v_float32x4 brighter = r > zero;
      const v_float32x4 z = r * inv_scale4;
      const v_float32x4 z2 = cv::v_select(brighter, z * z, zero);
      const v_float32x4 d = one / (one + z2);
      const v_float32x4 sqrt_w = sqrt_pw * d;
      const v_float32x4 term =
          sqrt_pw * sqrt_pw * cv::v_select(brighter, half_scale2_4 * z2 * d, half * r * r);
      const v_float32x4 wr = sqrt_w * r;
      cost2 = cost2 + cv::v_cvt_f64(term) + cv::v_cvt_f64_high(term);
      const v_float32x4 wr2 = wr * wr;
      wsq2 = wsq2 + cv::v_cvt_f64(wr2) + cv::v_cvt_f64_high(wr2);
      cv::v_store(wr_out + i, wr);
      const v_float32x4 ag = sqrt_w * a4 * g * inv_s2_4;
      cv::v_store(j[0] + i, ag * dx);
      cv::v_store(j[1] + i, ag * dy);
      cv::v_store(j[2] + i, ag * r2);
      cv::v_store(j[3] + i, sqrt_w * g);
      cv::v_store(j[4] + i, sqrt_w);
      cv::v_store(j[5] + i, sqrt_w * qx);
      cv::v_store(j[6] + i, sqrt_w * qy);
      cv::v_store(j[7] + i, sqrt_w * qxx);
      cv::v_store(j[8] + i, sqrt_w * qxy);
      cv::v_store(j[9] + i, sqrt_w * qyy);
      if constexpr (kReflection) {
        const v_float32x4 agr = sqrt_w * ar4 * gr * inv_sr2_4;
        cv::v_store(j[kR] + i, agr * dxr);
        cv::v_store(j[kR + 1] + i, agr * dyr);
        cv::v_store(j[kR + 2] + i, agr * rr2);
        cv::v_store(j[kR + 3] + i, sqrt_w * gr);
      }
    }
    cost = cv::v_reduce_sum(cost2);
    wsq = cv::v_reduce_sum(wsq2);
#else
    for (int i = 0; i < padded; ++i) {
      const float dx = xs[i] - u, dy = ys[i] - v;
      const float r2 = dx * dx + dy * dy;
      const float g = FastExp(r2 * gauss);
      const float qx = basis[0][i], qy = basis[1][i];
      const float qxx = basis[2][i], qxy = basis[3][i], qyy = basis[4][i];
      float model = b[0] + b[1] * qx + b[2] * qy + b[3] * qxx + b[4] * qxy + b[5] * qyy + a * g;
      float dxr = 0.0f, dyr = 0.0f, rr2 = 0.0f, gr = 0.0f;
      if constexpr (kReflection) {
        dxr = xs[i] - ur;
        dyr = ys[i] - vr;
        rr2 = dxr * dxr + dyr * dyr;
        gr = FastExp(rr2 * gauss_r);
        model += ar * gr;
      }
      float sqrt_pw = valid[i];
      if (tapered) {
        const float below = std::max(dy, 0.0f);
        sqrt_pw *= FastExp(below * below * taper_k);
      }
      if (values[i] >= kFullScale && model >= kFullScale) sqrt_pw = 0.0f;
      const float r = values[i] - model;
      const float z2 = r > 0.0f ? (r * inv_scale) * (r * inv_scale) : 0.0f;
      const float d = 1.0f / (1.0f + z2);
      const float sqrt_w = sqrt_pw * d;
      cost += sqrt_pw * sqrt_pw * (r > 0.0f ? half_scale2 * z2 * d : 0.5f * r * r);
      const float wr = sqrt_w * r;
      wsq += wr * wr;
      wr_out[i] = wr;
      const float ag = sqrt_w * a * g * inv_s2;
      j[0][i] = ag * dx;
      j[1][i] = ag * dy;
      j[2][i] = ag * r2;
      j[3][i] = sqrt_w * g;
      j[4][i] = sqrt_w;
      j[5][i] = sqrt_w * qx;
      j[6][i] = sqrt_w * qy;
      j[7][i] = sqrt_w * qxx;
      j[8][i] = sqrt_w * qxy;
      j[9][i] = sqrt_w * qyy;
      if constexpr (kReflection) {
        const float agr = sqrt_w * ar * gr * inv_sr2;
        j[kR][i] = agr * dxr;
        j[kR + 1][i] = agr * dyr;
        j[kR + 2][i] = agr * rr2;
        j[kR + 3][i] = sqrt_w * gr;
      }
    }
#endif
    *sum_sq = wsq;
    return cost;
  };
  // The normal equations of the columns the last evaluate() with the Jacobian wrote.
  auto normal_equations = [&](Mat* jtj, Vec* jtr) {
    Eigen::Matrix<float, kParams, kParams> h = Eigen::Matrix<float, kParams, kParams>::Zero();
    h.template selfadjointView<Eigen::Lower>().rankUpdate(weighted_j.transpose());
    *jtj = h.template cast<double>().template selfadjointView<Eigen::Lower>();
    *jtr = (weighted_j.transpose() * weighted_r).template cast<double>();
  };

  // Levenberg-Marquardt where a trial point is evaluated with its Jacobian rows at once:
  // accepted, its normal equations (the rank update, ~40 % of a fit) are formed for the next
  // step; rejected, only the damping changes. The weighted squared residual of the accepted
  // point is kept for the RMS instead of a last evaluation.
  Mat jtj;
  Vec jtr;
  double weighted_sq = 0.0;
  double cost = evaluate(theta, &weighted_sq);
  normal_equations(&jtj, &jtr);
  double lambda = 1e-3;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    Mat damped = jtj;
    damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-6);
    const Vec step = damped.ldlt().solve(jtr);
    if (!step.allFinite()) break;
    Vec candidate = theta + step;
    if constexpr (kReflection) {
      // Keep the second component a reflection: directly below the light (1.5 to 5 sigma plus a
      // few pixels, within a sigma sideways), wider (1 to 2.5 times), and dimmer.
      const double s = std::exp(candidate[2]);
      candidate[kR] = std::clamp(candidate[kR], candidate[0] - s, candidate[0] + s);
      candidate[kR + 1] =
          std::clamp(candidate[kR + 1], candidate[1] + 1.5 * s, candidate[1] + 5.0 * s + 4.0);
      candidate[kR + 2] = std::clamp(candidate[kR + 2], candidate[2], candidate[2] + std::log(2.5));
      candidate[kR + 3] = std::clamp(candidate[kR + 3], 0.0, std::max(0.0, candidate[3]));
    }
    double candidate_weighted_sq = 0.0;
    const double candidate_cost = evaluate(candidate, &candidate_weighted_sq);
    if (candidate_cost < cost) {
      theta = candidate;
      cost = candidate_cost;
      weighted_sq = candidate_weighted_sq;
      normal_equations(&jtj, &jtr);
      lambda = std::max(1e-7, lambda * 0.3);
      if (std::abs(step[0]) < 5e-3 && std::abs(step[1]) < 5e-3) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e6) break;
    }
  }
  FitResult result;
  result.u = theta[0];
  result.v = theta[1];
  result.sigma = std::exp(theta[2]);
  result.amplitude = theta[3];
  result.rms = std::sqrt(weighted_sq / num_samples);
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
// most about max_pixels; coordinates relative to (cx, cy).
FitSamples CollectSamples(const cv::Mat& image, int channel, int cx, int cy, int x0, int x1,
                          int y0, int y1, int max_pixels) {
  x0 = std::max(0, x0);
  y0 = std::max(0, y0);
  x1 = std::min(image.cols - 1, x1);
  y1 = std::min(image.rows - 1, y1);
  FitSamples samples;
  samples.ox = cx;
  samples.oy = cy;
  if (x0 > x1 || y0 > y1) return samples;
  const double area = static_cast<double>(x1 - x0 + 1) * (y1 - y0 + 1);
  const int stride = std::max(1, static_cast<int>(std::ceil(std::sqrt(area / max_pixels))));
  // The first grid column and row inside the window (cx, cy may lie outside it when the light's
  // centre is off the image: the remainder must then be taken towards +infinity, not 0).
  const int xs = x0 + (((cx - x0) % stride) + stride) % stride;
  const int ys = y0 + (((cy - y0) % stride) + stride) % stride;
  const int channels = image.channels();
  const size_t capacity = static_cast<size_t>(area / (stride * stride)) + 4 + kFitLanes;
  samples.x.reserve(capacity);
  samples.y.reserve(capacity);
  samples.value.reserve(capacity);
  for (int y = ys; y <= y1; y += stride) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = xs; x <= x1; x += stride) {
      samples.x.push_back(static_cast<float>(x - cx));
      samples.y.push_back(static_cast<float>(y - cy));
      samples.value.push_back(static_cast<float>(row[channels * x + channel]));
    }
  }
  samples.count = static_cast<int>(samples.x.size());
  const int padded = (samples.count + kFitLanes - 1) / kFitLanes * kFitLanes;
  samples.valid.assign(padded, 0.0f);
  std::fill(samples.valid.begin(), samples.valid.begin() + samples.count, 1.0f);
  samples.x.resize(padded, 0.0f);
  samples.y.resize(padded, 0.0f);
  samples.value.resize(padded, 0.0f);
  return samples;
}

// Fits a light (FitModel<10>, tapered below), then, if it is bright enough for a reflection to
// show, refits with the reflection term in a window reaching below it (FitModel<14>).
FitResult FitLight(const cv::Mat& image, int channel, const FitStart& start, double noise,
                   int max_pixels, double taper_sigmas, bool model_reflection) {
  const int cx = static_cast<int>(std::lround(start.u));
  const int cy = static_cast<int>(std::lround(start.v));
  const int half = static_cast<int>(std::ceil(3.0 * start.sigma)) + 2;
  FitResult result;
  {
    const FitSamples samples = CollectSamples(image, channel, cx, cy, cx - half, cx + half,
                                              cy - half, cy + half, max_pixels);
    if (samples.count < 12) return result;
    // Only a starting point when the reflection model follows.
    result = FitModel<10>(samples, start, noise, taper_sigmas, model_reflection ? 8 : 15);
  }
  // A reflection is worth modelling only where it can show: at a quarter of the light's
  // amplitude it must stand above the noise.
  if (!model_reflection || !result.ok || 0.25 * result.amplitude < 3.0 * noise) return result;
  const FitStart refined{result.u, result.v, result.sigma, result.amplitude};
  // The window reaches 4.5 sigma below the light (most of a reflection a few sigma down) and
  // 2.5 sigma to the sides; wider, it takes in more background than the quadratic describes.
  const int below = static_cast<int>(std::ceil(4.5 * refined.sigma + 3.0));
  const int side = static_cast<int>(std::ceil(2.5 * refined.sigma)) + 2;
  const int half2 = static_cast<int>(std::ceil(3.0 * refined.sigma)) + 2;
  const int cx2 = static_cast<int>(std::lround(refined.u));
  const int cy2 = static_cast<int>(std::lround(refined.v));
  const FitSamples samples = CollectSamples(image, channel, cx2, cy2, cx2 - side, cx2 + side,
                                            cy2 - half2, cy2 + below, max_pixels);
  if (samples.count < 20) return result;
  const FitResult two_component = FitModel<14>(samples, refined, noise, 0.0, 15);
  // The second component must be what it is meant to be: a dimmer blob below the light, not the
  // light itself (the fit can swap the two).
  const bool plausible = two_component.ok &&
                         two_component.reflection_amplitude < two_component.amplitude &&
                         two_component.reflection_v > two_component.v + 0.5 * two_component.sigma &&
                         std::hypot(two_component.u - result.u, two_component.v - result.v) <
                             0.5 * result.sigma + 1.0;
  return plausible ? two_component : result;
}

// Per-channel mean over the disc of radius max(1, sigma / 2) around (u, v), and whether the disc
// reaches full scale.
void CentralDisc(const cv::Mat& image, double u, double v, double sigma,
                 std::array<double, 3>* mean, std::array<bool, 3>* clipped) {
  const double radius = std::max(1.0, 0.5 * sigma);
  const int channels = image.channels();
  std::array<double, 3> sum{};
  int count = 0;
  *clipped = {false, false, false};
  for (int y = std::max(0, static_cast<int>(std::floor(v - radius)));
       y <= std::min(image.rows - 1, static_cast<int>(std::ceil(v + radius))); ++y) {
    const uint8_t* row = image.ptr<uint8_t>(y);
    for (int x = std::max(0, static_cast<int>(std::floor(u - radius)));
         x <= std::min(image.cols - 1, static_cast<int>(std::ceil(u + radius))); ++x) {
      if ((x - u) * (x - u) + (y - v) * (y - v) > radius * radius) continue;
      ++count;
      for (int c = 0; c < channels; ++c) {
        sum[c] += row[channels * x + c];
        if (row[channels * x + c] >= kFullScale) (*clipped)[c] = true;
      }
    }
  }
  for (int c = 0; c < channels; ++c) (*mean)[c] = count > 0 ? sum[c] / count : 0.0;
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
      // Squared distances: no hypot per pixel.
      const double d2 = (x - u) * (x - u) + (y - v) * (y - v);
      const uint8_t* pixel = row + 3 * x;
      if (d2 <= core * core) {
        for (int c = 0; c < 3; ++c) sum[c] += pixel[c];
        ++count;
      } else if (d2 >= ring_in * ring_in && d2 <= ring_out * ring_out) {
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

// A connected component of the threshold mask: its pixels in raster order, bounding box and
// brightest (smoothed) pixel, the first in raster order among equals.
struct Component {
  std::vector<uint32_t> pixels;  // packed coordinates
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  uint32_t brightest = 0;
};

// A horizontal run of mask pixels, [x0, x1] on row y, and its union-find parent.
struct Run {
  int y, x0, x1, parent;
};

int FindRun(std::vector<Run>& runs, int r) {
  while (runs[r].parent != r) {
    runs[r].parent = runs[runs[r].parent].parent;
    r = runs[r].parent;
  }
  return r;
}

// 8-connected components of a CV_8U mask (non-zero = set) by union-find on its runs: the mask is
// scanned once, skipping empty stretches eight bytes at a time, and only the runs (a few hundred
// on a frame) are labelled, never a full-size label image. cv::connectedComponents writes a
// CV_32S label image that then has to be read back to gather the pixels: ~0.55 ms on a 640 x 512
// frame against ~0.1 ms here. Components come in the raster order of their first pixel.
std::vector<Component> LabelComponents(const cv::Mat& mask, const cv::Mat& smoothed) {
  const int rows = mask.rows;
  const int cols = mask.cols;
  std::vector<Run> runs;
  size_t previous_begin = 0, previous_end = 0;  // runs of row y - 1
  for (int y = 0; y < rows; ++y) {
    const uint8_t* m = mask.ptr<uint8_t>(y);
    const size_t row_begin = runs.size();
    int x = 0;
    while (x < cols) {
      if (x + 8 <= cols) {
        uint64_t chunk;
        std::memcpy(&chunk, m + x, sizeof(chunk));
        if (chunk == 0) {
          x += 8;
          continue;
        }
      }
      if (m[x] == 0) {
        ++x;
        continue;
      }
      const int x0 = x;
      while (x < cols && m[x] != 0) ++x;
      const int self = static_cast<int>(runs.size());
      runs.push_back({y, x0, x - 1, self});
    }
    // Join each new run with the runs of the row above that touch it (8-connected: overlapping
    // or diagonally adjacent); the root is always the earliest run.
    if (previous_end > previous_begin && runs[previous_begin].y == y - 1) {
      size_t j = previous_begin;
      for (size_t i = row_begin; i < runs.size(); ++i) {
        while (j < previous_end && runs[j].x1 < runs[i].x0 - 1) ++j;
        for (size_t k = j; k < previous_end && runs[k].x0 <= runs[i].x1 + 1; ++k) {
          const int a = FindRun(runs, static_cast<int>(i));
          const int b = FindRun(runs, static_cast<int>(k));
          if (a != b) runs[std::max(a, b)].parent = std::min(a, b);
        }
      }
    }
    if (runs.size() > row_begin) {
      previous_begin = row_begin;
      previous_end = runs.size();
    }
  }

  std::vector<Component> components;
  std::vector<int> component_of_root(runs.size(), -1);
  std::vector<int> best_level;
  for (size_t i = 0; i < runs.size(); ++i) {
    const Run& run = runs[i];
    const int root = FindRun(runs, static_cast<int>(i));
    int& id = component_of_root[root];
    if (id < 0) {
      id = static_cast<int>(components.size());
      components.emplace_back();
      components.back().x0 = run.x0;
      components.back().y0 = run.y;
      components.back().x1 = run.x1;
      components.back().y1 = run.y;
      best_level.push_back(-1);
    }
    Component& component = components[id];
    component.x0 = std::min(component.x0, run.x0);
    component.x1 = std::max(component.x1, run.x1);
    component.y1 = run.y;
    const uint8_t* level = smoothed.ptr<uint8_t>(run.y);
    for (int x = run.x0; x <= run.x1; ++x) {
      component.pixels.push_back(Pack(x, run.y));
      if (level[x] > best_level[id]) {
        best_level[id] = level[x];
        component.brightest = Pack(x, run.y);
      }
    }
  }
  return components;
}

// Segments one scale of the smoothed luma into blobs: pixels brighter than the coarse background
// by the threshold, grouped into 8-connected components (LabelComponents), each split at its
// significant maxima. Fills the blobs' pixels, luma contrast, luma energy and full-resolution
// bounding box; `scale` is the downsampling factor of `smoothed` and smoothed_noise its noise
// sigma. Returns the threshold used.
double SegmentScale(const cv::Mat& smoothed, double smoothed_noise, int scale,
                    const LightDetectorOptions& options, int background_window_cells,
                    double min_area, double max_area_fraction, int full_cols, int full_rows,
                    std::vector<Blob>* blobs) {
  const int rows = smoothed.rows;
  const int cols = smoothed.cols;
  double threshold =
      std::max(options.min_contrast, options.threshold_noise_sigmas * smoothed_noise);

  const CoarseBackground background(smoothed, options.background_grid_cols,
                                    options.background_close_cells, background_window_cells);
  if (options.threshold == LightThreshold::kOtsu) {
    // Otsu's cut of the background-subtracted image; the noise-based threshold is its floor.
    cv::Mat background8, excess, unused;
    background.plane(0).convertTo(background8, CV_8U);
    cv::resize(background8, background8, smoothed.size(), 0, 0, cv::INTER_LINEAR);
    cv::subtract(smoothed, background8, excess);  // saturates negatives to 0
    threshold = std::max(threshold, cv::threshold(excess, unused, 0, 255,
                                                  cv::THRESH_BINARY | cv::THRESH_OTSU));
  }
  // Pixels above background + threshold; the level is interpolated in 8 bit (half a gray level
  // of rounding is far below the threshold).
  cv::Mat level;
  background.plane(0).convertTo(level, CV_8U, 1.0, threshold);
  cv::resize(level, level, smoothed.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat mask;
  cv::compare(smoothed, level, mask, cv::CMP_GT);
  const std::vector<Component> components = LabelComponents(mask, smoothed);
  if (components.empty()) return threshold;

  const size_t max_area = static_cast<size_t>(max_area_fraction * rows * cols);
  const size_t first = blobs->size();
  for (const Component& component : components) {
    if (static_cast<double>(component.pixels.size()) * scale * scale < min_area ||
        component.pixels.size() > max_area) {
      continue;
    }
    // No blob of a component can be brighter than the component's brightest pixel.
    const int tx = PackedX(component.brightest), ty = PackedY(component.brightest);
    if (smoothed.ptr<uint8_t>(ty)[tx] - background.At(0, tx, ty) < options.min_peak_contrast) {
      continue;
    }
    SplitComponent(smoothed, component.pixels, component.x0, component.y0,
                   component.x1 - component.x0 + 1, component.y1 - component.y0 + 1,
                   options.min_prominence, blobs);
  }
  for (size_t i = first; i < blobs->size(); ++i) {
    Blob& blob = (*blobs)[i];
    blob.scale = scale;
    const int tx = PackedX(blob.pixels.front()), ty = PackedY(blob.pixels.front());
    const double bg = background.At(0, tx, ty);
    blob.luma_contrast = smoothed.ptr<uint8_t>(ty)[tx] - bg;
    int x0 = cols, y0 = rows, x1 = -1, y1 = -1;
    int64_t level_sum = 0;
    for (uint32_t p : blob.pixels) {
      const int x = PackedX(p), y = PackedY(p);
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
      level_sum += smoothed.ptr<uint8_t>(y)[x];
    }
    blob.luma_energy = (static_cast<double>(level_sum) - bg * blob.pixels.size()) * scale * scale;
    blob.area = static_cast<double>(blob.pixels.size()) * scale * scale;
    blob.x0 = x0 * scale;
    blob.y0 = y0 * scale;
    blob.x1 = std::min(full_cols - 1, (x1 + 1) * scale - 1);
    blob.y1 = std::min(full_rows - 1, (y1 + 1) * scale - 1);
    blob.at_border = x0 <= 0 || y0 <= 0 || x1 >= cols - 1 || y1 >= rows - 1;
  }
  return threshold;
}

// Colour measurements of a blob at full resolution against a local background (per-channel
// median of a ring just outside its bounding box): per-channel contrast, energy and clipping,
// the channel to measure the position in, the red ratio, and a first centroid, sigma and
// elongation. Returns false when the blob has no usable signal.
bool MeasureBlob(const cv::Mat& image, const LightDetectorOptions& options, Blob* blob) {
  const int rows = image.rows;
  const int cols = image.cols;
  const int channels = image.channels();
  const int f = blob->scale;

  // Local background: up to ~256 samples on a ring three pixels (times the scale) outside the
  // bounding box.
  const int margin = 3 * f;
  const int rx0 = std::max(0, blob->x0 - margin), rx1 = std::min(cols - 1, blob->x1 + margin);
  const int ry0 = std::max(0, blob->y0 - margin), ry1 = std::min(rows - 1, blob->y1 + margin);
  const int perimeter = 2 * ((rx1 - rx0) + (ry1 - ry0)) + 4;
  const int ring_step = std::max(1, perimeter / 256);
  std::array<std::vector<uint8_t>, 3> ring;
  auto sample = [&](int x, int y) {
    const uint8_t* pixel = image.ptr<uint8_t>(y) + channels * x;
    for (int c = 0; c < channels; ++c) ring[c].push_back(pixel[c]);
  };
  for (int x = rx0; x <= rx1; x += ring_step) {
    sample(x, ry0);
    sample(x, ry1);
  }
  for (int y = ry0; y <= ry1; y += ring_step) {
    sample(rx0, y);
    sample(rx1, y);
  }
  // The 10th percentile: a ring can cross brighter things (a neighbouring light, a reflection,
  // the lit deck around a dark light housing); it is the darkest part that is background.
  std::array<double, 3>& bg = blob->background;
  for (int c = 0; c < channels; ++c) {
    std::vector<uint8_t>& r = ring[c];
    std::nth_element(r.begin(), r.begin() + r.size() / 10, r.end());
    bg[c] = r[r.size() / 10];
  }

  // Visit the blob's pixels at full resolution, each standing for `weight` pixels: a coarse pixel
  // by the centre of its f x f block, and a large fine blob by every k-th pixel of its list
  // (which is ordered by brightness, so the sample spans all levels and keeps the brightest).
  constexpr size_t kMaxVisits = 3000;
  const size_t stride = std::max<size_t>(1, (blob->pixels.size() + kMaxVisits - 1) / kMaxVisits);
  const double weight = static_cast<double>(stride) * f * f;
  auto for_each_pixel = [&](auto&& visit) {
    for (size_t i = 0; i < blob->pixels.size(); i += stride) {
      const int x = std::min(cols - 1, PackedX(blob->pixels[i]) * f + f / 2);
      const int y = std::min(rows - 1, PackedY(blob->pixels[i]) * f + f / 2);
      visit(x, y, image.ptr<uint8_t>(y) + channels * x);
    }
  };
  std::array<double, 3> peak{}, energy{}, saturated{};
  double count = 0.0;
  for_each_pixel([&](int, int, const uint8_t* pixel) {
    count += weight;
    for (int c = 0; c < channels; ++c) {
      peak[c] = std::max<double>(peak[c], pixel[c]);
      energy[c] += weight * (pixel[c] - bg[c]);
      if (pixel[c] >= kSaturatedLevel) saturated[c] += weight;
    }
  });
  blob->peak = *std::max_element(peak.begin(), peak.begin() + channels);

  // A channel counts as clipped when more than a couple of pixels are at full scale (a small
  // particle on the blob may clip one or two).
  const double clipped_pixels = 3.0;
  double best_contrast = 0.0;
  int most_energy = 0;
  for (int c = 0; c < channels; ++c) {
    blob->channel_contrast[c] = peak[c] - bg[c];
    blob->channel_saturated[c] = saturated[c] >= clipped_pixels;
    best_contrast = std::max(best_contrast, blob->channel_contrast[c]);
    if (energy[c] > energy[most_energy]) most_energy = c;
  }
  // The position is measured in the unclipped channel with the most light (energy, which a small
  // particle on the blob hardly changes) if it has enough contrast; otherwise in the clipped
  // channel with the smallest clipped core, which is the light's own (a reflection or a
  // neighbour merges into a larger plateau in a more strongly clipped channel).
  const double usable = std::min(options.min_fit_contrast, 0.25 * best_contrast);
  int best_unclipped = -1;
  for (int c = 0; c < channels; ++c) {
    if (blob->channel_saturated[c] || blob->channel_contrast[c] < usable) continue;
    if (best_unclipped < 0 || energy[c] > energy[best_unclipped]) best_unclipped = c;
  }
  if (best_unclipped >= 0) {
    blob->channel = best_unclipped;
  } else {
    blob->channel = most_energy;
    for (int c = 0; c < channels; ++c) {
      if (blob->channel_contrast[c] >= usable && saturated[c] < saturated[blob->channel]) {
        blob->channel = c;
      }
    }
  }
  if (channels == 3) blob->red_ratio = energy[2] / std::max({1.0, energy[0], energy[1]});

  // First estimate: centroid of the measuring channel above half its peak; sigma from the area
  // above half the peak (pi 2 ln 2 s^2 for a Gaussian).
  const int c = blob->channel;
  const double half_level = bg[c] + 0.5 * blob->channel_contrast[c];
  double sw = 0.0, su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0;
  double half_area = 0.0;
  for_each_pixel([&](int x, int y, const uint8_t* pixel) {
    const double w = weight * (pixel[c] - half_level);
    if (w <= 0.0) return;
    half_area += weight;
    sw += w;
    su += w * x;
    sv += w * y;
    suu += w * x * x;
    svv += w * y * y;
    suv += w * x * y;
  });
  if (sw <= 0.0) return false;
  blob->u = su / sw;
  blob->v = sv / sw;
  const double cuu = suu / sw - blob->u * blob->u;
  const double cvv = svv / sw - blob->v * blob->v;
  const double cuv = suv / sw - blob->u * blob->v;
  const double mean = 0.5 * (cuu + cvv);
  const double spread = std::sqrt(0.25 * (cuu - cvv) * (cuu - cvv) + cuv * cuv);
  blob->elongation = std::sqrt((mean + spread) / std::max(1e-6, mean - spread));
  // A clipped blob's half-level region is wider than 2 ln 2 s^2 by its clipped core: with r^2 =
  // area / pi, r_half^2 - r_clipped^2 = 2 ln 2 s^2 whatever the hidden amplitude.
  blob->amplitude = std::max(1.0, blob->channel_contrast[c]);
  blob->sigma = std::sqrt(std::max(0.25, (half_area - saturated[c]) / (2.0 * kPi * std::log(2.0))));
  return true;
}

// A fitted light.
struct Light {
  const Blob* blob = nullptr;
  double u = 0.0, v = 0.0, sigma = 0.0, amplitude = 0.0, rms = 0.0;
  double max_contrast = 0.0;
  std::array<double, 3> core{};        // per channel: mean of the central disc - background
  std::array<bool, 3> core_clipped{};  // per channel: the central disc reaches full scale
  bool rejected = false;
};

}  // namespace

LightDetector::LightDetector(const LightDetectorOptions& options)
    : options_(options), dehazer_(options.dehaze_options) {
  const LightDetectorOptions& o = options_;
  if (!(o.prefilter_sigma_px >= 0.0) || o.median_ksize < 0 || o.background_grid_cols < 2 ||
      o.background_close_cells < 0 || o.background_window_cells < 1 || o.coarse_scale < 0 ||
      o.coarse_background_window_cells < 1 || o.min_area_px < 1 || !(o.max_area_fraction > 0.0) ||
      o.max_fit_pixels < 16 || !(o.min_contrast >= 0.0) || !(o.min_prominence >= 0.0) ||
      !(o.max_fit_shift_sigmas > 0.0) || !(o.reflection_max_ratio > 0.0)) {
    throw std::invalid_argument("LightDetectorOptions: a size or threshold is out of range");
  }
}

std::vector<LightDetection> LightDetector::Detect(const cv::Mat& bgr8) const {
  if (bgr8.empty()) throw std::invalid_argument("LightDetector: empty image");
  if (bgr8.depth() != CV_8U || (bgr8.channels() != 1 && bgr8.channels() != 3)) {
    throw std::invalid_argument("LightDetector: image must be 8-bit BGR or gray");
  }
  if (bgr8.cols > 0xFFFF || bgr8.rows > 0xFFFF) {
    throw std::invalid_argument("LightDetector: image larger than 65535 pixels");
  }
  cv::Mat image = options_.dehaze ? dehazer_.Dehaze(bgr8).image : bgr8;
  if (!image.isContinuous()) image = image.clone();
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
  const double sf = std::max(0.0, options_.prefilter_sigma_px);
  if (sf > 0.0) {
    const int k = 2 * static_cast<int>(std::ceil(2.0 * sf)) + 1;  // +-2 sigma
    cv::GaussianBlur(smoothed, smoothed, cv::Size(k, k), sf, sf, cv::BORDER_REPLICATE);
  }
  if (!smoothed.isContinuous()) smoothed = smoothed.clone();
  // A Gaussian pre-filter of sigma s averages about 4 pi s^2 pixels of white noise.
  const double noise = EstimateNoiseSigma(luma, 0);
  const double smoothed_noise =
      sf > 0.0 ? noise / (2.0 * std::sqrt(kPi) * std::max(0.5, sf)) : noise;
  std::array<double, 3> channel_noise{-1.0, -1.0, -1.0};  // filled when first needed
  auto noise_of = [&](int c) {
    if (channel_noise[c] < 0.0) channel_noise[c] = std::max(0.5, EstimateNoiseSigma(image, c));
    return channel_noise[c];
  };

  // Pre-fit checks: contrast, size, shape, and particles by colour.
  auto passes = [&](const Blob& blob) {
    if (blob.luma_contrast < options_.min_peak_contrast || blob.area < options_.min_area_px) {
      return false;
    }
    // A blob cut by the image border looks elongated (a half disc: 1.9) whatever it is.
    if (blob.elongation > (blob.at_border ? 1.6 : 1.0) * options_.max_elongation) return false;
    if (options_.reject_particles && channels == 3 &&
        blob.sigma <= options_.particle_max_sigma_px &&
        blob.red_ratio >= options_.particle_min_red_ratio) {
      return false;
    }
    return true;
  };

  std::vector<Blob> blobs;
  const double threshold =
      SegmentScale(smoothed, smoothed_noise, 1, options_, options_.background_window_cells,
                   options_.min_area_px, options_.max_area_fraction, cols, rows, &blobs);
  // Fits a candidate at full resolution and keeps it if the fit describes a light.
  std::vector<Light> lights;
  auto fit_and_check = [&](const Blob& blob) {
    const int c = blob.channel;
    const double noise_c = noise_of(c);
    const FitResult fit = FitLight(image, c, {blob.u, blob.v, blob.sigma, blob.amplitude}, noise_c,
                                   options_.max_fit_pixels, options_.fit_taper_sigmas,
                                   options_.model_reflections);
    // The coarse scale is there for big lights only.
    const double min_coarse_sigma = 0.5 * options_.coarse_min_sigma_px * cols / 640.0;
    if (!fit.ok || (blob.scale > 1 && fit.sigma < min_coarse_sigma)) return false;
    Light light;
    light.blob = &blob;
    light.u = fit.u;
    light.v = fit.v;
    light.sigma = fit.sigma;
    light.amplitude = fit.amplitude;
    light.rms = fit.rms;
    for (int k = 0; k < channels; ++k) {
      light.max_contrast = std::max(light.max_contrast, blob.channel_contrast[k]);
    }
    // The fit must stay on the blob it started from (a fit that slides onto a neighbour or a
    // deck edge moves by more than a fraction of its own sigma).
    const double shift = std::hypot(fit.u - blob.u, fit.v - blob.v) / std::max(0.5, fit.sigma);
    // The model must explain the blob's centre: a fit that drifted onto a faint bump beside a
    // bright plateau leaves most of the centre unexplained.
    CentralDisc(image, fit.u, fit.v, fit.sigma, &light.core, &light.core_clipped);
    const double central = light.core[c] - fit.background;
    const double explained = std::min(0.94 * fit.amplitude, kFullScale - fit.background);
    // Size against brightness: a light that looks big is near, and a near light is bright, so a
    // blob must rise by a minimum per pixel of sigma (per 640 pixels of image width, since sigma
    // scales with the focal length). The brightness is the fit's amplitude (which sees through
    // clipping and ignores a particle on the blob), scaled to the blob's brightest channel; a
    // clipped blob has a lower bar, since clipping leaves its amplitude uncertain.
    const bool clipped =
        light.core_clipped[0] || light.core_clipped[1] || light.core_clipped[2];
    const double size = fit.sigma * 640.0 / cols;
    const double min_contrast = (clipped ? options_.min_clipped_contrast_per_sigma
                                         : options_.min_contrast_per_sigma) * size;
    const double brightness =
        fit.amplitude * std::max(1.0, light.max_contrast / std::max(1.0, blob.channel_contrast[c]));
    const bool too_big_unclipped =
        !clipped && options_.max_unclipped_sigma_px > 0.0 && size > options_.max_unclipped_sigma_px;
    if (central > 2.0 * explained + 3.0 * noise_c || shift > options_.max_fit_shift_sigmas ||
        fit.sigma < options_.min_sigma_px || brightness < min_contrast || too_big_unclipped) {
      return false;
    }
    // Particles: small and white (marine snow under the lamp), unlike the blue-green lights,
    // whose red is absorbed long before they look that small.
    if (options_.reject_particles && channels == 3 &&
        fit.sigma <= options_.particle_max_sigma_px &&
        CoreRedRatio(image, fit.u, fit.v, fit.sigma) >= options_.particle_min_red_ratio) {
      return false;
    }
    for (int k = 0; k < channels; ++k) light.core[k] -= blob.background[k];
    lights.push_back(light);
    return true;
  };

  // Reflections: a dimmer blob just below a brighter one, as far below as a reflection's geometry
  // allows (a few source sigmas). Dimmer means a fainter core in the source's measuring channel;
  // where that channel clips at the source's core, unclipped in some channel in which the source
  // clips (a nearer light below a clipped one clips too).
  auto is_reflection = [&](const Light& source, const Light& candidate) {
    const double s = std::max(0.8, source.sigma);
    const double dv = candidate.v - source.v;
    const double du = std::abs(candidate.u - source.u);
    if (dv < options_.reflection_min_offset_sigmas * s ||
        dv > options_.reflection_max_offset_sigmas * s + options_.reflection_max_offset_px ||
        du > options_.reflection_max_lateral_sigmas * s + 3.0) {
      return false;
    }
    const int c = source.blob->channel;
    if (!source.core_clipped[c]) {
      return candidate.core[c] < options_.reflection_max_ratio * source.core[c];
    }
    for (int k = 0; k < channels; ++k) {
      if (source.core_clipped[k] && !candidate.core_clipped[k]) return true;
    }
    return false;
  };

  // Brightest first, so that a light is fitted before its reflection, which is then recognised
  // (and not fitted) from its first centroid.
  std::vector<Blob*> fine_order;
  for (Blob& blob : blobs) {
    if (blob.luma_contrast >= options_.min_peak_contrast && blob.area >= options_.min_area_px) {
      fine_order.push_back(&blob);
    }
  }
  std::sort(fine_order.begin(), fine_order.end(),
            [](const Blob* a, const Blob* b) { return a->luma_contrast > b->luma_contrast; });
  cv::Mat owner(rows, cols, CV_8U, cv::Scalar(0));  // 1 where a fine-scale light was found
  for (Blob* blob : fine_order) {
    if (!MeasureBlob(image, options_, blob) || !passes(*blob)) continue;
    if (options_.reject_reflections) {
      Light provisional;
      provisional.blob = blob;
      provisional.u = blob->u;
      provisional.v = blob->v;
      provisional.sigma = blob->sigma;
      CentralDisc(image, blob->u, blob->v, blob->sigma, &provisional.core,
                  &provisional.core_clipped);
      for (int k = 0; k < channels; ++k) provisional.core[k] -= blob->background[k];
      const bool reflection =
          std::any_of(lights.begin(), lights.end(),
                      [&](const Light& light) { return is_reflection(light, provisional); });
      if (reflection) continue;
    }
    if (!fit_and_check(*blob)) continue;
    for (uint32_t p : blob->pixels) owner.ptr<uint8_t>(PackedY(p))[PackedX(p)] = 1;
  }
  // Lights bigger than the background window (the last metre of the landing) are found on a
  // downsampled image with a wide window; only the big ones are kept from that scale, and only
  // where the fine scale found no light.
  const int f = options_.coarse_scale;
  std::vector<Blob> coarse_blobs;
  if (f >= 2 && cols / f >= 16 && rows / f >= 16) {
    cv::Mat small;
    cv::resize(smoothed, small, cv::Size(cols / f, rows / f), 0, 0, cv::INTER_AREA);
    const double min_sigma = options_.coarse_min_sigma_px * cols / 640.0;
    SegmentScale(small, smoothed_noise / f, f, options_, options_.coarse_background_window_cells,
                 2.0 * kPi * min_sigma * min_sigma, 1.0, cols, rows, &coarse_blobs);
    for (Blob& blob : coarse_blobs) {
      if (blob.area < 2.0 * kPi * min_sigma * min_sigma ||
          blob.luma_contrast < options_.min_peak_contrast) {
        continue;
      }
      if (!MeasureBlob(image, options_, &blob) || blob.sigma < min_sigma || !passes(blob)) {
        continue;
      }
      const int x = std::clamp(static_cast<int>(std::lround(blob.u)), 0, cols - 1);
      const int y = std::clamp(static_cast<int>(std::lround(blob.v)), 0, rows - 1);
      if (owner.at<uint8_t>(y, x)) continue;
      fit_and_check(blob);
    }
  }

  // The same light found twice (by both scales, or as two blobs): keep the first, which comes
  // from the finer scale.
  for (size_t i = 0; i < lights.size(); ++i) {
    if (lights[i].rejected) continue;
    for (size_t j = i + 1; j < lights.size(); ++j) {
      if (lights[j].rejected) continue;
      const double d = std::hypot(lights[i].u - lights[j].u, lights[i].v - lights[j].v);
      if (d < 0.5 * std::max(lights[i].sigma, lights[j].sigma) + 1.0) lights[j].rejected = true;
    }
  }

  // Reflections found after the fit (two blobs whose fits converged close together, or a
  // reflection fitted before its source).
  if (options_.reject_reflections) {
    std::vector<size_t> order(lights.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
      return lights[a].blob->luma_contrast > lights[b].blob->luma_contrast;
    });
    for (size_t j : order) {
      if (lights[j].rejected) continue;
      for (Light& candidate : lights) {
        if (!candidate.rejected && &candidate != &lights[j] &&
            is_reflection(lights[j], candidate)) {
          candidate.rejected = true;
        }
      }
    }
  }

  std::vector<LightDetection> detections;
  for (const Light& light : lights) {
    if (light.rejected) continue;
    LightDetection d;
    d.uv = Eigen::Vector2d(light.u, light.v);
    d.radius_px = std::sqrt(light.blob->area / kPi);
    d.peak = light.blob->peak;
    // Confidence: contrast well above the threshold, a fit that explains the blob (residual small
    // against the amplitude), and a size clear of the particle range.
    const double contrast_term = 1.0 - std::exp(-light.max_contrast / (4.0 * threshold));
    const double fit_term = std::exp(-light.rms / std::max(1.0, 0.1 * light.amplitude));
    const double size_term = std::min(1.0, light.sigma / 1.5);
    d.score = std::clamp(contrast_term * fit_term * size_term, 0.0, 1.0);
    detections.push_back(d);
  }
  std::sort(detections.begin(), detections.end(),
            [](const LightDetection& a, const LightDetection& b) { return a.score > b.score; });
  return detections;
}

}  // namespace auvdock
