#include "auvdock/vision/learned_light_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/vision/field_deinterlace.h"
#include "auvdock/vision/image_levels.h"

namespace auvdock {

struct LearnedLightDetector::Network {
  cv::dnn::Net net;
};

namespace {

constexpr int kCellsX = LearnedLightDetector::kInputWidth / LearnedLightDetector::kStride;
constexpr int kCellsY = LearnedLightDetector::kInputHeight / LearnedLightDetector::kStride;

// A 1 x C x 64 x 80 blob's channel c as a 64 x 80 matrix (a copy).
cv::Mat Channel(const cv::Mat& blob, int c, const std::string& name, const std::string& path) {
  if (blob.dims != 4 || blob.size[0] != 1 || blob.size[1] <= c || blob.size[2] != kCellsY ||
      blob.size[3] != kCellsX || blob.type() != CV_32F) {
    throw std::runtime_error(path + ": output '" + name +
                             "' does not have the shape 1 x C x 64 x 80 (float) the detector "
                             "expects (learned_light_detector.h)");
  }
  return cv::Mat(kCellsY, kCellsX, CV_32F,
                 const_cast<float*>(blob.ptr<float>(0, c)))
      .clone();
}

// p(i, j) is at least every neighbour's, and strictly above those before it in raster order (one
// maximum per plateau).
bool LocalMaximum(const cv::Mat& p, int i, int j) {
  const float v = p.at<float>(i, j);
  for (int di = -1; di <= 1; ++di) {
    for (int dj = -1; dj <= 1; ++dj) {
      if (di == 0 && dj == 0) continue;
      const int y = i + di, x = j + dj;
      if (y < 0 || x < 0 || y >= p.rows || x >= p.cols) continue;
      const float w = p.at<float>(y, x);
      const bool before = di < 0 || (di == 0 && dj < 0);
      if (w > v || (before && w == v)) return false;
    }
  }
  return true;
}

}  // namespace

std::string VerifyLightProposal(const LightCore& core, const LightCandidateEvidence& evidence,
                                double noise_sigma, bool has_colour,
                                const LearnedLightDetectorOptions& options) {
  const double contrast = core.peak - core.floor;
  if (contrast < std::max(options.min_contrast, options.min_contrast_noise_sigmas * noise_sigma)) {
    return "no contrast";
  }
  LightCandidateCheckOptions checks = options.checks;
  checks.colour = options.colour;
  return CheckRidgeAndColour(evidence, has_colour, checks);
}

LearnedLightDetector::LearnedLightDetector(const LearnedLightDetectorOptions& options)
    : options_(options), net_(std::make_unique<Network>()) {
  if (!(options.min_probability > 0.0 && options.min_probability < 1.0) ||
      !(options.refine_radius_sigmas >= 0.0) || !(options.min_refine_radius_px >= 0.0) ||
      !(options.proposal_sigma_fraction > 0.0) || !(options.proposal_floor_px > 0.0) ||
      !(options.border_sigma_fraction >= 0.0) || !(options.min_separation_px >= 0.0) ||
      options.max_detections < 1) {
    throw std::invalid_argument("LearnedLightDetectorOptions out of range");
  }
  try {
    net_->net = cv::dnn::readNetFromONNX(options.model_path);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(options.model_path + ": not a network OpenCV can load (" +
                             std::string(e.what()).substr(0, 200) + ")");
  }
  if (net_->net.empty()) {
    throw std::runtime_error(options.model_path + ": not a network OpenCV can load");
  }
  net_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  // One pass on a blank image: checks the outputs' names and shapes now, not on the first frame.
  Infer(cv::Mat(kInputHeight, kInputWidth, CV_8UC3, cv::Scalar::all(0)));
}

LearnedLightDetector::~LearnedLightDetector() = default;

LearnedLightDetector::Maps LearnedLightDetector::Infer(const cv::Mat& bgr) const {
  cv::Mat input;
  if (bgr.cols == kInputWidth && bgr.rows == kInputHeight) {
    input = bgr;
  } else {
    cv::resize(bgr, input, cv::Size(kInputWidth, kInputHeight), 0, 0, cv::INTER_AREA);
  }
  const cv::Mat blob = cv::dnn::blobFromImage(input, 1.0 / 255.0, cv::Size(), cv::Scalar(),
                                              /*swapRB=*/false, /*crop=*/false, CV_32F);
  std::vector<cv::Mat> outputs;
  const std::vector<std::string> names{"heatmap", "offset", "log_sigma"};
  {
    std::lock_guard<std::mutex> lock(mutex_);
    net_->net.setInput(blob, "image");
    try {
      net_->net.forward(outputs, names);
    } catch (const cv::Exception& e) {
      throw std::runtime_error(options_.model_path +
                               ": the network does not run on a 1 x 3 x 256 x 320 input with "
                               "outputs heatmap, offset, log_sigma (" +
                               std::string(e.what()).substr(0, 200) + ")");
    }
  }
  Maps maps;
  maps.probability = Channel(outputs[0], 0, names[0], options_.model_path);
  maps.offset_x = Channel(outputs[1], 0, names[1], options_.model_path);
  maps.offset_y = Channel(outputs[1], 1, names[1], options_.model_path);
  maps.log_sigma = Channel(outputs[2], 0, names[2], options_.model_path);
  return maps;
}

std::vector<LightDetection> LearnedLightDetector::Detect(const cv::Mat& image) const {
  if (image.empty() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) {
    throw std::invalid_argument(
        "LearnedLightDetector: expected a non-empty CV_8UC3 or CV_8UC1 image");
  }
  const cv::Mat source = options_.deinterlace ? LineDoubleEvenField(image) : image;
  cv::Mat bgr, gray;
  if (source.channels() == 3) {
    bgr = source;
    cv::cvtColor(source, gray, cv::COLOR_BGR2GRAY);
  } else {
    gray = source;
    cv::cvtColor(source, bgr, cv::COLOR_GRAY2BGR);
  }
  const Maps maps = Infer(bgr);
  const double sx = static_cast<double>(kInputWidth) / source.cols;
  const double sy = static_cast<double>(kInputHeight) / source.rows;
  const double scale = std::sqrt(sx * sy);

  struct Proposal {
    double u, v, sigma, probability;
  };
  std::vector<Proposal> proposals;
  for (int i = 0; i < kCellsY; ++i) {
    for (int j = 0; j < kCellsX; ++j) {
      const float p = maps.probability.at<float>(i, j);
      if (p < options_.min_probability || !LocalMaximum(maps.probability, i, j)) continue;
      const double x_in = kStride * (j + std::clamp(maps.offset_x.at<float>(i, j), 0.0f, 1.0f));
      const double y_in = kStride * (i + std::clamp(maps.offset_y.at<float>(i, j), 0.0f, 1.0f));
      const double sigma =
          std::exp(std::clamp(static_cast<double>(maps.log_sigma.at<float>(i, j)), -3.0, 6.0)) /
          scale;
      proposals.push_back({(x_in + 0.5) / sx - 0.5, (y_in + 0.5) / sy - 0.5,
                           std::max(sigma, 0.5), p});
    }
  }
  std::sort(proposals.begin(), proposals.end(),
            [](const Proposal& a, const Proposal& b) { return a.probability > b.probability; });

  cv::Mat luma;
  gray.convertTo(luma, CV_32F);
  const double noise = EstimatePixelNoise(luma);
  const bool has_colour = source.channels() == 3 && options_.colour != LightColour::kWhite;
  const double background_excess = has_colour ? MedianColourExcess(source, options_.colour) : 0.0;
  LightCandidateCheckOptions checks = options_.checks;
  checks.colour = options_.colour;

  std::vector<LightDetection> out;
  for (const Proposal& proposal : proposals) {
    if (static_cast<int>(out.size()) >= options_.max_detections) break;
    const int x = std::clamp(static_cast<int>(std::lround(proposal.u)), 0, source.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(proposal.v)), 0, source.rows - 1);
    const Eigen::Vector2d proposed(proposal.u, proposal.v);
    LightDetection d;
    d.score = proposal.probability;
    const auto core = MeasureLightCore(luma, x, y, proposal.sigma, noise, options_.core);
    const double reach =
        std::max(options_.refine_radius_sigmas * proposal.sigma, options_.min_refine_radius_px);
    const bool refined = core && !core->touches_window && (core->uv - proposed).norm() <= reach;
    // The core the checks measure: the refined one, or a disc of radius sigma at the proposal
    // (its floor and peak from the core's window when there is one).
    LightCore measured;
    if (refined) {
      measured = *core;
    } else {
      measured.uv = proposed;
      measured.radius_px = proposal.sigma;
      measured.peak = core ? core->peak : luma.at<float>(y, x);
      measured.floor = core ? core->floor : measured.peak;
    }
    const LightCandidateEvidence evidence = MeasureCandidateEvidence(
        source, luma, measured, proposal.sigma, background_excess, checks);
    if (options_.verify &&
        !VerifyLightProposal(measured, evidence, noise, has_colour, options_).empty()) {
      continue;
    }
    d.uv = measured.uv;
    d.peak = measured.peak;
    d.colour_excess = has_colour ? evidence.halo_excess : 0.0;
    if (refined) {
      d.covariance = core->covariance;
      d.radius_px = std::max(core->radius_px, proposal.sigma);
    } else {
      const double s =
          std::max(options_.proposal_sigma_fraction * proposal.sigma, options_.proposal_floor_px);
      d.covariance = s * s * Eigen::Matrix2d::Identity();
      d.radius_px = proposal.sigma;
    }
    const double halo = 2.0 * proposal.sigma;
    d.at_border = d.uv.x() - halo < -0.5 || d.uv.y() - halo < -0.5 ||
                  d.uv.x() + halo > source.cols - 0.5 || d.uv.y() + halo > source.rows - 0.5;
    if (d.at_border) {
      const double s = options_.border_sigma_fraction * proposal.sigma;
      d.covariance += s * s * Eigen::Matrix2d::Identity();
    }
    const bool duplicate = std::any_of(out.begin(), out.end(), [&](const LightDetection& k) {
      return (k.uv - d.uv).norm() <
             std::max({options_.min_separation_px, k.radius_px, d.radius_px});
    });
    if (!duplicate) out.push_back(d);
  }
  return out;
}

}  // namespace auvdock
