#include "auvdock/vision/dark_channel_dehazer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

// Padding value of the running minimum: it never wins against an image value.
template <typename T>
constexpr T PadValue() {
  return std::numeric_limits<T>::has_infinity ? std::numeric_limits<T>::infinity()
                                              : std::numeric_limits<T>::max();
}

// van Herk / Gil-Werman along each row. The row is padded with anchor values in front and
// window - 1 - anchor behind, then cut into blocks of `window` samples. Within a block, forward
// holds the running minimum from the block start and backward the one to the block end; the
// window starting at padded index x spans at most two blocks, so its minimum is
// min(backward[x], forward[x + window - 1]).
template <typename T>
void HorizontalMinPass(const cv::Mat& src, int window, cv::Mat* dst) {
  const int n = src.cols;
  const int anchor = window / 2;
  const int m = n + window - 1;
  const T pad = PadValue<T>();
  std::vector<T> padded(m, pad), forward(m), backward(m);
  for (int y = 0; y < src.rows; ++y) {
    const T* in = src.ptr<T>(y);
    std::copy(in, in + n, padded.begin() + anchor);
    for (int begin = 0; begin < m; begin += window) {
      const int end = std::min(begin + window, m);
      forward[begin] = padded[begin];
      for (int i = begin + 1; i < end; ++i) forward[i] = std::min(forward[i - 1], padded[i]);
      backward[end - 1] = padded[end - 1];
      for (int i = end - 2; i >= begin; --i) backward[i] = std::min(backward[i + 1], padded[i]);
    }
    T* out = dst->ptr<T>(y);
    for (int x = 0; x < n; ++x) out[x] = std::min(backward[x], forward[x + window - 1]);
  }
}

// The same recursion down the columns, done on whole rows at a time so that the inner loops run
// along memory (and vectorise).
template <typename T>
void VerticalMinPass(const cv::Mat& src, int window, cv::Mat* dst) {
  const int rows = src.rows;
  const int cols = src.cols;
  const int anchor = window / 2;
  const int m = rows + window - 1;
  const std::vector<T> pad_row(cols, PadValue<T>());
  auto padded = [&](int i) -> const T* {
    const int y = i - anchor;
    return (y >= 0 && y < rows) ? src.ptr<T>(y) : pad_row.data();
  };
  cv::Mat forward(m, cols, src.type());
  cv::Mat backward(m, cols, src.type());
  for (int begin = 0; begin < m; begin += window) {
    const int end = std::min(begin + window, m);
    std::copy(padded(begin), padded(begin) + cols, forward.ptr<T>(begin));
    for (int i = begin + 1; i < end; ++i) {
      const T* prev = forward.ptr<T>(i - 1);
      const T* in = padded(i);
      T* out = forward.ptr<T>(i);
      for (int x = 0; x < cols; ++x) out[x] = std::min(prev[x], in[x]);
    }
    std::copy(padded(end - 1), padded(end - 1) + cols, backward.ptr<T>(end - 1));
    for (int i = end - 2; i >= begin; --i) {
      const T* next = backward.ptr<T>(i + 1);
      const T* in = padded(i);
      T* out = backward.ptr<T>(i);
      for (int x = 0; x < cols; ++x) out[x] = std::min(next[x], in[x]);
    }
  }
  for (int y = 0; y < rows; ++y) {
    const T* a = backward.ptr<T>(y);
    const T* b = forward.ptr<T>(y + window - 1);
    T* out = dst->ptr<T>(y);
    for (int x = 0; x < cols; ++x) out[x] = std::min(a[x], b[x]);
  }
}

template <typename T>
cv::Mat MinFilterTyped(const cv::Mat& src, int window) {
  if (window == 1) return src.clone();
  cv::Mat horizontal(src.size(), src.type());
  HorizontalMinPass<T>(src, window, &horizontal);
  cv::Mat result(src.size(), src.type());
  VerticalMinPass<T>(horizontal, window, &result);
  return result;
}

#if CV_SIMD128
// 16 BGR pixels from `in` as floats: (*f)[c][k] holds channel c of pixels 4k .. 4k + 3.
inline void ExpandToFloat(const uint8_t* in, std::array<std::array<cv::v_float32x4, 4>, 3>* f) {
  std::array<cv::v_uint8x16, 3> bgr;
  cv::v_load_deinterleave(in, bgr[0], bgr[1], bgr[2]);
  for (int c = 0; c < 3; ++c) {
    cv::v_uint16x8 low, high;
    cv::v_expand(bgr[c], low, high);
    std::array<cv::v_uint32x4, 4> words;
    cv::v_expand(low, words[0], words[1]);
    cv::v_expand(high, words[2], words[3]);
    for (int k = 0; k < 4; ++k) (*f)[c][k] = cv::v_cvt_f32(cv::v_reinterpret_as_s32(words[k]));
  }
}
#endif

// Per-pixel minimum over the colour channels, CV_8U.
cv::Mat ChannelMinimum(const cv::Mat& image) {
  if (image.channels() == 1) return image.clone();
  cv::Mat result(image.size(), CV_8U);
  for (int y = 0; y < image.rows; ++y) {
    const uint8_t* in = image.ptr<uint8_t>(y);
    uint8_t* out = result.ptr<uint8_t>(y);
    int x = 0;
#if CV_SIMD128
    for (; x + 16 <= image.cols; x += 16) {
      cv::v_uint8x16 b, g, r;
      cv::v_load_deinterleave(in + 3 * x, b, g, r);
      cv::v_store(out + x, cv::v_min(cv::v_min(b, g), r));
    }
#endif
    for (; x < image.cols; ++x) out[x] = std::min({in[3 * x], in[3 * x + 1], in[3 * x + 2]});
  }
  return result;
}

// Mean colour of the `count` pixels with the largest dark channel. Ties at the cut-off level are
// taken in raster order, so exactly `count` pixels are averaged and the result is deterministic.
cv::Vec3d AtmosphericLight(const cv::Mat& image, const cv::Mat& dark, int count) {
  // Four interleaved partial histograms: the dark channel is smooth, so neighbours fall into the
  // same bin and a single histogram serialises on that counter (store-to-load forwarding); this
  // loop was ~20 % of Dehaze.
  std::array<std::array<int, 256>, 4> partial{};
  for (int y = 0; y < dark.rows; ++y) {
    const uint8_t* d = dark.ptr<uint8_t>(y);
    int x = 0;
    for (; x + 4 <= dark.cols; x += 4) {
      ++partial[0][d[x]];
      ++partial[1][d[x + 1]];
      ++partial[2][d[x + 2]];
      ++partial[3][d[x + 3]];
    }
    for (; x < dark.cols; ++x) ++partial[0][d[x]];
  }
  std::array<int, 256> histogram{};
  for (int b = 0; b < 256; ++b) {
    histogram[b] = partial[0][b] + partial[1][b] + partial[2][b] + partial[3][b];
  }
  int level = 255;
  int above = 0;  // pixels with dark > level
  while (level > 0 && above + histogram[level] < count) above += histogram[level--];
  int at_level_wanted = count - above;

  const int channels = image.channels();
  cv::Vec3d sum(0.0, 0.0, 0.0);
  for (int y = 0; y < dark.rows; ++y) {
    const uint8_t* d = dark.ptr<uint8_t>(y);
    const uint8_t* in = image.ptr<uint8_t>(y);
    // Most rows hold none of the 0.1 % brightest: a vectorised maximum rules them out.
    uint8_t row_max = 0;
    for (int x = 0; x < dark.cols; ++x) row_max = std::max(row_max, d[x]);
    if (row_max < level) continue;
    for (int x = 0; x < dark.cols; ++x) {
      const bool take = d[x] > level || (d[x] == level && at_level_wanted-- > 0);
      if (!take) continue;
      const uint8_t* pixel = in + channels * x;
      for (int c = 0; c < 3; ++c) sum[c] += pixel[channels == 3 ? c : 0];
    }
  }
  return sum / static_cast<double>(count);
}

// He's guided filter (ECCV 2010, algorithm 1) with box windows of radius r: the output is locally
// a linear function a I + b of the guide I that best fits p in the least-squares sense, with
// a ridge eps on a. Box filters are running sums, so the cost does not depend on r.
cv::Mat GuidedFilter(const cv::Mat& guide, const cv::Mat& p, int radius, double epsilon) {
  const cv::Size box(2 * radius + 1, 2 * radius + 1);
  auto mean = [&](const cv::Mat& x) {
    cv::Mat m;
    cv::boxFilter(x, m, CV_32F, box, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
    return m;
  };
  const cv::Mat mean_i = mean(guide);
  const cv::Mat mean_p = mean(p);
  const cv::Mat corr_ii = mean(guide.mul(guide));
  const cv::Mat corr_ip = mean(guide.mul(p));
  const cv::Mat var_i = corr_ii - mean_i.mul(mean_i);
  const cv::Mat cov_ip = corr_ip - mean_i.mul(mean_p);
  cv::Mat a;
  cv::divide(cov_ip, var_i + epsilon, a);
  const cv::Mat b = mean_p - a.mul(mean_i);
  return mean(a).mul(guide) + mean(b);
}

}  // namespace

cv::Mat MinFilter(const cv::Mat& src, int window) {
  if (src.empty()) throw std::invalid_argument("MinFilter: empty image");
  if (window < 1) throw std::invalid_argument("MinFilter: window must be >= 1");
  switch (src.type()) {
    case CV_8UC1:
      return MinFilterTyped<uint8_t>(src, window);
    case CV_32FC1:
      return MinFilterTyped<float>(src, window);
    default:
      throw std::invalid_argument("MinFilter: image must be CV_8UC1 or CV_32FC1");
  }
}

DarkChannelDehazer::DarkChannelDehazer(const DehazeOptions& options) : options_(options) {
  if (options_.window < 1) throw std::invalid_argument("DehazeOptions: window must be >= 1");
  if (!(options_.omega >= 0.0 && options_.omega <= 1.0)) {
    throw std::invalid_argument("DehazeOptions: omega must be in [0, 1]");
  }
  if (!(options_.t_min > 0.0 && options_.t_min <= 1.0)) {
    throw std::invalid_argument("DehazeOptions: t_min must be in (0, 1]");
  }
  if (!(options_.top_fraction > 0.0 && options_.top_fraction <= 1.0)) {
    throw std::invalid_argument("DehazeOptions: top_fraction must be in (0, 1]");
  }
  if (options_.guided_radius < 1) {
    throw std::invalid_argument("DehazeOptions: guided_radius must be >= 1");
  }
  if (!(options_.guided_epsilon > 0.0)) {
    throw std::invalid_argument("DehazeOptions: guided_epsilon must be > 0");
  }
}

DarkChannelDehazer::Result DarkChannelDehazer::Dehaze(const cv::Mat& bgr8) const {
  if (bgr8.empty()) throw std::invalid_argument("DarkChannelDehazer: empty image");
  if (bgr8.type() != CV_8UC3 && bgr8.type() != CV_8UC1) {
    throw std::invalid_argument("DarkChannelDehazer: image must be CV_8UC3 (BGR) or CV_8UC1");
  }
  const int channels = bgr8.channels();
  const int rows = bgr8.rows;
  const int cols = bgr8.cols;
  Result result;

  // Eq. 1.
  result.dark_channel = MinFilter(ChannelMinimum(bgr8), options_.window);

  const double num_pixels = static_cast<double>(rows) * cols;
  const int count = static_cast<int>(std::clamp(std::lround(options_.top_fraction * num_pixels), 1L,
                                                static_cast<long>(num_pixels)));
  result.atmospheric_light = AtmosphericLight(bgr8, result.dark_channel, count);
  // A channel with no veiling light at all would divide by zero in eq. 3; one gray level is the
  // smallest value an 8-bit image can show.
  std::array<float, 3> inv_a;
  std::array<float, 3> a;
  for (int c = 0; c < 3; ++c) {
    a[c] = static_cast<float>(std::max(1.0, result.atmospheric_light[c]));
    inv_a[c] = 1.0f / a[c];
  }

  // Eq. 3: dark channel of I / A.
  cv::Mat normalized_min(rows, cols, CV_32F);
  for (int y = 0; y < rows; ++y) {
    const uint8_t* in = bgr8.ptr<uint8_t>(y);
    float* out = normalized_min.ptr<float>(y);
    if (channels == 3) {
      int x = 0;
#if CV_SIMD128
      const cv::v_float32x4 inv_b4 = cv::v_setall_f32(inv_a[0]);
      const cv::v_float32x4 inv_g4 = cv::v_setall_f32(inv_a[1]);
      const cv::v_float32x4 inv_r4 = cv::v_setall_f32(inv_a[2]);
      for (; x + 16 <= cols; x += 16) {
        std::array<std::array<cv::v_float32x4, 4>, 3> f;
        ExpandToFloat(in + 3 * x, &f);
        for (int k = 0; k < 4; ++k) {
          cv::v_store(out + x + 4 * k, cv::v_min(cv::v_min(f[0][k] * inv_b4, f[1][k] * inv_g4),
                                                 f[2][k] * inv_r4));
        }
      }
#endif
      for (; x < cols; ++x) {
        const uint8_t* pixel = in + 3 * x;
        out[x] = std::min({pixel[0] * inv_a[0], pixel[1] * inv_a[1], pixel[2] * inv_a[2]});
      }
    } else {
      for (int x = 0; x < cols; ++x) out[x] = in[x] * inv_a[0];
    }
  }
  cv::Mat transmission = MinFilter(normalized_min, options_.window);
  transmission.convertTo(transmission, CV_32F, -options_.omega, 1.0);
  if (options_.refine_with_guided_filter) {
    cv::Mat gray;
    if (channels == 3) {
      cv::cvtColor(bgr8, gray, cv::COLOR_BGR2GRAY);
    } else {
      gray = bgr8;
    }
    gray.convertTo(gray, CV_32F, 1.0 / 255.0);
    transmission =
        GuidedFilter(gray, transmission, options_.guided_radius, options_.guided_epsilon);
  }
  const float t_min = static_cast<float>(options_.t_min);
  for (int y = 0; y < rows; ++y) {
    float* t = transmission.ptr<float>(y);
    for (int x = 0; x < cols; ++x) t[x] = std::clamp(t[x], t_min, 1.0f);
  }
  result.transmission = transmission;

  // Eq. 4.
  result.image.create(rows, cols, bgr8.type());
  for (int y = 0; y < rows; ++y) {
    const uint8_t* in = bgr8.ptr<uint8_t>(y);
    const float* t = transmission.ptr<float>(y);
    uint8_t* out = result.image.ptr<uint8_t>(y);
    int x = 0;
#if CV_SIMD128
    // The scalar loop's arithmetic lane by lane, in the same order and precision (float
    // subtract, multiply, add; round to nearest even as cvRound; saturate to 0-255 as
    // saturate_cast), so the output is bit-identical.
    if (channels == 3) {
      const cv::v_float32x4 one = cv::v_setall_f32(1.0f);
      const std::array<cv::v_float32x4, 3> a4{cv::v_setall_f32(a[0]), cv::v_setall_f32(a[1]),
                                              cv::v_setall_f32(a[2])};
      for (; x + 16 <= cols; x += 16, in += 48, out += 48) {
        std::array<cv::v_float32x4, 4> inv_t;
        for (int k = 0; k < 4; ++k) inv_t[k] = one / cv::v_load(t + x + 4 * k);
        std::array<std::array<cv::v_float32x4, 4>, 3> f;
        ExpandToFloat(in, &f);
        std::array<cv::v_uint8x16, 3> packed;
        for (int c = 0; c < 3; ++c) {
          std::array<cv::v_int32x4, 4> j;
          for (int k = 0; k < 4; ++k) j[k] = cv::v_round((f[c][k] - a4[c]) * inv_t[k] + a4[c]);
          packed[c] = cv::v_pack_u(cv::v_pack(j[0], j[1]), cv::v_pack(j[2], j[3]));
        }
        cv::v_store_interleave(out, packed[0], packed[1], packed[2]);
      }
    }
#endif
    for (; x < cols; ++x) {
      const float inv_t = 1.0f / t[x];
      for (int c = 0; c < channels; ++c, ++in, ++out) {
        *out = cv::saturate_cast<uint8_t>((*in - a[c]) * inv_t + a[c]);
      }
    }
  }
  return result;
}

}  // namespace auvdock
