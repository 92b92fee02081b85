// Dark-channel-prior dehazing of underwater images (He, Sun and Tang, "Single image haze removal
// using dark channel prior", CVPR 2009 / TPAMI 2011), as seed 000 (Zhu et al. 2025, section
// 2.1.1, eqs. 1-4) uses it before looking for the dock's guide lights, with omega = 0.5.
//
// Math, per pixel x, colour channel c in {B, G, R}, square window Omega(x) of side `window`:
//   eq. 1  dark channel     I_dark(x) = min_{y in Omega(x)} min_c I^c(y)
//   eq. 2  haze model       I(x) = J(x) t(x) + A (1 - t(x))
//          atmospheric (veiling) light A^c = mean of I^c over the top_fraction (0.1 %) of pixels
//          with the largest dark channel (seed 000's wording; He et al. pick the brightest of
//          them instead, which a single saturated pixel can spoil)
//   eq. 3  transmission     t(x) = 1 - omega min_{y in Omega(x)} min_c I^c(y) / A^c,
//          optionally refined by He's guided filter (ECCV 2010) with the gray image as guide,
//          then clamped to [t_min, 1]
//   eq. 4  recovery         J^c(x) = (I^c(x) - A^c) / t(x) + A^c, clipped to [0, 255]
// omega = 0 leaves the image unchanged; omega = 1 removes all the haze the prior explains.
//
// Cost: linear in the number of pixels and independent of the window size. MinFilter is the van
// Herk / Gil-Werman running minimum (about three comparisons per pixel and pass), the guided
// filter uses box filters (running sums), the atmospheric light a 256-bin histogram. The
// per-pixel loops (channel minimum, eq. 3's I / A, eq. 4) run 16 pixels at a time with OpenCV's
// universal intrinsics, with the scalar arithmetic lane by lane (bit-identical output).
// Timings: benchmarks/vision_frontend_benchmark.cc (BM_Dehaze).
//
// Units: 8-bit gray levels for images and A (0-255), transmission dimensionless in [t_min, 1].
// Frames: image pixels only. No state beyond the options; Dehaze() is const and thread-safe.
#pragma once

#include <opencv2/core.hpp>

namespace auvdock {

// Minimum over the window x window square around every pixel of a single-channel CV_8U or CV_32F
// image, in O(1) per pixel per pass (a horizontal then a vertical van Herk / Gil-Werman pass).
// The square spans columns x - window/2 .. x - window/2 + window - 1 (and the same for rows),
// i.e. it is centred for odd windows and has OpenCV's default anchor for even ones. Near the
// border it is clamped to the image (pixels outside are ignored). The result equals
//   cv::erode(src, dst, cv::getStructuringElement(cv::MORPH_RECT, {window, window}))
// exactly, with erode's default border (a constant +max, which never wins a minimum) and equally
// with cv::BORDER_REPLICATE (a replicated edge pixel is already inside the clamped window).
// NaNs are not supported. Throws std::invalid_argument for an empty image, another type or
// window < 1.
cv::Mat MinFilter(const cv::Mat& src, int window);

struct DehazeOptions {
  int window = 15;                         // side of Omega, pixels (He et al.: 15)
  double omega = 0.5;                      // haze kept: 0 = no dehazing, 1 = all (seed 000: 0.5)
  double t_min = 0.1;                      // lower bound of t, limits noise amplification
  double top_fraction = 0.001;             // share of brightest dark-channel pixels for A
  bool refine_with_guided_filter = false;  // He's guided filter on t (soft-matting substitute)
  int guided_radius = 20;                  // box radius r of the guided filter, pixels
  double guided_epsilon = 1e-3;            // regulariser, with the guide scaled to [0, 1]
};

class DarkChannelDehazer {
 public:
  // Throws std::invalid_argument for window < 1, omega outside [0, 1], t_min outside (0, 1],
  // top_fraction outside (0, 1], guided_radius < 1 or guided_epsilon <= 0.
  explicit DarkChannelDehazer(const DehazeOptions& options = {});

  struct Result {
    cv::Mat image;                 // recovered J, same type as the input (CV_8UC3 or CV_8UC1)
    cv::Mat dark_channel;          // CV_8U, eq. 1 of the input
    cv::Mat transmission;          // CV_32F, eq. 3 as used in eq. 4 (refined, clamped)
    cv::Vec3d atmospheric_light;   // A, B G R, 0-255 (all three equal for a gray input)
  };

  // Dehazes a CV_8UC3 BGR image; a CV_8UC1 image is treated as a one-channel (gray) image.
  // Throws std::invalid_argument for an empty image or any other type.
  Result Dehaze(const cv::Mat& bgr8) const;

  const DehazeOptions& options() const { return options_; }

 private:
  DehazeOptions options_;
};

}  // namespace auvdock
