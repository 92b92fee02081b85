#include "auvdock/vision/light_candidate_checks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

constexpr int kRingSamples = 24;
constexpr int kHaloRings = 3;
constexpr int kSectors = 8;
constexpr double kPi = 3.14159265358979323846;

constexpr double kMinSurroundingsGapPx = 6.0;

// The quantile of the colour excess on a ring of kRingSamples points (those inside the image);
// -infinity when the whole ring is outside.
double SurroundingsExcess(const cv::Mat& bgr, const Eigen::Vector2d& centre, double radius,
                          LightColour colour, double quantile) {
  std::vector<double> excess;
  excess.reserve(kRingSamples);
  for (int s = 0; s < kRingSamples; ++s) {
    const double angle = 2.0 * kPi * s / kRingSamples;
    const int px = static_cast<int>(std::lround(centre.x() + radius * std::cos(angle)));
    const int py = static_cast<int>(std::lround(centre.y() + radius * std::sin(angle)));
    if (px < 0 || py < 0 || px >= bgr.cols || py >= bgr.rows) continue;
    const cv::Vec3b& p = bgr.at<cv::Vec3b>(py, px);
    excess.push_back(ColourExcess(colour, p[0], p[1], p[2]));
  }
  if (excess.empty()) return -std::numeric_limits<double>::infinity();
  const size_t k = static_cast<size_t>(quantile * (excess.size() - 1));
  std::nth_element(excess.begin(), excess.begin() + k, excess.end());
  return excess[k];
}

// tr(H)^2 / det(H) of the Hessian of the luma smoothed at sigma, at the pixel nearest centre;
// +infinity unless H is negative definite (a blob's maximum).
double CurvatureRatio(const cv::Mat& luma, const Eigen::Vector2d& centre, double sigma) {
  const int cx = static_cast<int>(std::lround(centre.x()));
  const int cy = static_cast<int>(std::lround(centre.y()));
  const int reach = static_cast<int>(std::ceil(3.0 * sigma)) + 2;
  const cv::Rect window(cx - reach, cy - reach, 2 * reach + 1, 2 * reach + 1);
  const cv::Rect roi = window & cv::Rect(0, 0, luma.cols, luma.rows);
  // A blob cut by the image's edge is half a blob: its curvature across the edge is unknown (0:
  // not measured; the border's own checks judge it).
  if (roi != window) return 0.0;
  // At large scales on a patch shrunk by an integer factor to a sigma of ~2 of its pixels (the
  // ratio of curvatures does not depend on the pixel size): a few hundred pixels per candidate.
  const int factor = std::max(1, static_cast<int>(sigma / 2.0));
  cv::Mat patch = luma(roi);
  if (factor > 1) {
    cv::resize(patch, patch, cv::Size(std::max(3, roi.width / factor), std::max(3, roi.height / factor)),
               0, 0, cv::INTER_AREA);
  }
  const double s = sigma / factor;
  cv::Mat smooth;
  cv::GaussianBlur(patch, smooth, cv::Size(0, 0), s, s, cv::BORDER_REPLICATE);
  const int x = std::clamp(static_cast<int>(std::lround((cx - roi.x + 0.5) / factor - 0.5)), 1,
                           smooth.cols - 2);
  const int y = std::clamp(static_cast<int>(std::lround((cy - roi.y + 0.5) / factor - 0.5)), 1,
                           smooth.rows - 2);
  auto at = [&](int dx, int dy) { return static_cast<double>(smooth.at<float>(y + dy, x + dx)); };
  const double dxx = at(1, 0) - 2.0 * at(0, 0) + at(-1, 0);
  const double dyy = at(0, 1) - 2.0 * at(0, 0) + at(0, -1);
  const double dxy = 0.25 * (at(1, 1) - at(1, -1) - at(-1, 1) + at(-1, -1));
  const double trace = dxx + dyy;
  const double det = dxx * dyy - dxy * dxy;
  if (!(det > 0.0) || !(trace < 0.0)) return std::numeric_limits<double>::infinity();
  return trace * trace / det;
}

}  // namespace

LightCandidateEvidence MeasureCandidateEvidence(const cv::Mat& bgr, const cv::Mat& luma,
                                                const LightCore& core, double sigma_px,
                                                double background_excess,
                                                const LightCandidateCheckOptions& options) {
  LightCandidateEvidence evidence;
  const bool colour_image = bgr.type() == CV_8UC3;
  const double outer = std::max(options.halo_radius_sigmas * sigma_px, options.min_halo_radius_px);
  // The peak test on the outer ring; the colour on rings from just outside the core to it (a
  // halo's colour is strongest next to the white core, and fades into the background).
  evidence.halo_excess = -std::numeric_limits<double>::infinity();
  if (colour_image && options.surroundings_halo_radii > 0.0) {
    const double radius =
        std::max(options.surroundings_halo_radii * outer, outer + kMinSurroundingsGapPx);
    evidence.surroundings_excess =
        SurroundingsExcess(bgr, core.uv, radius, options.colour, options.surroundings_quantile) -
        background_excess;
  }
  const double inner = std::min(outer, std::max(core.radius_px + 1.0, 0.5 * outer));
  for (int ring = 0; ring < kHaloRings; ++ring) {
    const double rho = inner + (outer - inner) * ring / (kHaloRings - 1.0);
    std::array<double, kSectors> sector_luma{};
    std::array<int, kSectors> sector_count{};
    double excess_sum = 0.0;
    int excess_count = 0;
    for (int s = 0; s < kRingSamples; ++s) {
      const double angle = 2.0 * kPi * s / kRingSamples;
      const int px = static_cast<int>(std::lround(core.uv.x() + rho * std::cos(angle)));
      const int py = static_cast<int>(std::lround(core.uv.y() + rho * std::sin(angle)));
      if (px < 0 || py < 0 || px >= luma.cols || py >= luma.rows) {
        evidence.at_border = true;
        continue;
      }
      const int sector = s * kSectors / kRingSamples;
      sector_luma[sector] += luma.at<float>(py, px);
      ++sector_count[sector];
      if (colour_image) {
        const cv::Vec3b& p = bgr.at<cv::Vec3b>(py, px);
        excess_sum += ColourExcess(options.colour, p[0], p[1], p[2]);
        ++excess_count;
      }
    }
    if (excess_count > 0) {
      evidence.halo_excess =
          std::max(evidence.halo_excess, excess_sum / excess_count - background_excess);
    }
    if (ring == kHaloRings - 1) {
      std::vector<double> means;
      for (int k = 0; k < kSectors; ++k) {
        if (sector_count[k] > 0) means.push_back(sector_luma[k] / sector_count[k]);
      }
      std::sort(means.rbegin(), means.rend());
      evidence.peak_drop = means.empty() ? 0.0 : core.peak - means.front();
      const size_t open = std::min(means.size(), static_cast<size_t>(options.open_sectors));
      evidence.open_drop = means.size() < static_cast<size_t>(kSectors) - open + 1
                               ? evidence.peak_drop
                               : core.peak - means[kSectors - open];
    }
  }
  if (!std::isfinite(evidence.halo_excess)) evidence.halo_excess = 0.0;

  // Profile: the top (within sigma / 2, on a small grid) against the ring at sigma.
  double top_sum = 0.0, mid_sum = 0.0;
  int top_count = 0, mid_count = 0;
  const double half = 0.5 * sigma_px;
  const int reach = static_cast<int>(std::ceil(half));
  const int cu = static_cast<int>(std::lround(core.uv.x()));
  const int cv = static_cast<int>(std::lround(core.uv.y()));
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const int px = cu + dx, py = cv + dy;
      if (dx * dx + dy * dy > half * half + 0.5 || px < 0 || py < 0 || px >= luma.cols ||
          py >= luma.rows) {
        continue;
      }
      top_sum += luma.at<float>(py, px);
      ++top_count;
      if (colour_image) {
        const cv::Vec3b& p = bgr.at<cv::Vec3b>(py, px);
        const double brightest = std::max({p[0], p[1], p[2]});
        evidence.saturated = evidence.saturated || brightest >= options.saturation_level;
      } else {
        evidence.saturated =
            evidence.saturated || luma.at<float>(py, px) >= options.saturation_level;
      }
    }
  }
  for (int s = 0; s < kRingSamples; ++s) {
    const double angle = 2.0 * kPi * s / kRingSamples;
    const int px = static_cast<int>(std::lround(core.uv.x() + sigma_px * std::cos(angle)));
    const int py = static_cast<int>(std::lround(core.uv.y() + sigma_px * std::sin(angle)));
    if (px < 0 || py < 0 || px >= luma.cols || py >= luma.rows) continue;
    mid_sum += luma.at<float>(py, px);
    ++mid_count;
  }
  if (options.max_curvature_ratio > 0.0) {
    evidence.curvature_ratio = CurvatureRatio(luma, core.uv, sigma_px);
  }
  if (top_count > 0 && mid_count > 0) {
    const double top = top_sum / top_count - core.floor;
    const double mid = mid_sum / mid_count - core.floor;
    evidence.flatness = top > 0.0 ? mid / top : 1.0;
  }
  return evidence;
}

double MedianColourExcess(const cv::Mat& bgr, LightColour colour) {
  if (bgr.type() != CV_8UC3 || colour == LightColour::kWhite) return 0.0;
  std::vector<float> values;
  values.reserve(static_cast<size_t>(bgr.rows / 4 + 1) * (bgr.cols / 4 + 1));
  for (int y = 0; y < bgr.rows; y += 4) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < bgr.cols; x += 4) {
      values.push_back(static_cast<float>(ColourExcess(colour, row[x][0], row[x][1], row[x][2])));
    }
  }
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

std::string CheckLightCandidate(const BlobCandidate& candidate, const LightCore& core,
                                const LightCandidateEvidence& evidence, bool has_colour,
                                const LightCandidateCheckOptions& options) {
  if (core.touches_window || core.radius_px > options.max_core_radius_sigmas * candidate.sigma_px) {
    return "extended";
  }
  if (core.touches_border) return "cut by the border";
  const double stretch = options.max_core_stretch_px / std::max(core.radius_px, 1e-3);
  const double max_elongation =
      std::min(options.max_core_elongation, std::sqrt(1.0 + stretch * stretch / 3.0));
  if (core.elongation > max_elongation && core.area_px >= 12) return "elongated";
  // A core cut from a structure by the opening has that structure in part of its ring: like a
  // saturated light beside a bright surface, it must drop in the open sectors, not in all.
  const bool structure_beside = evidence.saturated || core.separated;
  const double contrast = core.peak - core.floor;
  if ((!core.separated && evidence.peak_drop < options.min_peak_drop) ||
      (!structure_beside && evidence.peak_drop < options.min_peak_drop_fraction * contrast) ||
      (structure_beside && evidence.open_drop < options.min_open_drop_fraction * contrast)) {
    return "not a peak";
  }
  if (core.radius_px < options.small_core_sigmas * candidate.sigma_px &&
      evidence.peak_drop < options.small_core_min_drop_fraction * contrast) {
    return "not a peak (a small bump on a larger structure)";
  }
  if (!evidence.saturated && candidate.sigma_px >= options.min_flat_sigma_px &&
      evidence.flatness > options.max_flatness) {
    return "flat top (a lit surface)";
  }
  return CheckRidgeAndColour(evidence, has_colour, options);
}

std::string CheckRidgeAndColour(const LightCandidateEvidence& evidence, bool has_colour,
                                const LightCandidateCheckOptions& options) {
  const double r = options.max_curvature_ratio;
  if (r > 0.0 && !(evidence.curvature_ratio <= (r + 1.0) * (r + 1.0) / r)) {
    return "a ridge (a line or an edge, not a blob)";
  }
  const bool colour_test = has_colour && options.colour != LightColour::kWhite;
  if (colour_test && options.surroundings_halo_radii > 0.0 && evidence.halo_excess > 0.0 &&
      evidence.halo_excess - evidence.surroundings_excess <
          options.min_own_colour_fraction * evidence.halo_excess) {
    return "the colour of its surroundings (halo excess " +
           std::to_string(std::lround(evidence.halo_excess)) + ", surroundings " +
           std::to_string(std::lround(evidence.surroundings_excess)) + ")";
  }
  if (colour_test && evidence.halo_excess < options.min_halo_excess) {
    return "wrong colour (halo excess " + std::to_string(std::lround(evidence.halo_excess)) +
           "; need " + std::to_string(std::lround(options.min_halo_excess)) + ")";
  }
  return {};
}

}  // namespace auvdock
