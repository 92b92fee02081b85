// Guide-light detector learned from randomised renders: the source paper's learned detector
// (seed 000: a single-stage network proposes the lights, then a threshold and a centroid inside
// each proposal give the centre), as a small fully convolutional network that predicts light
// centres as a heatmap (CenterNet-style: Zhou et al. 2019, "Objects as Points"), run through
// OpenCV's DNN module from an ONNX file (scripts/train_light_net.py trains and exports it; the
// shipped model is data/models/light_net.onnx).
//
// The network's contract (fixed input size, stride 4):
//   input  "image":     1 x 3 x 256 x 320 (N, C, H, W), BGR, pixel / 255; any image is resized
//                       to 320 x 256 (cv::INTER_AREA), with scales s_x = 320 / W, s_y = 256 / H;
//   output "heatmap":   1 x 1 x 64 x 80, the probability that a light's centre lies in cell
//                       (i, j), which covers input pixels [4j, 4j + 4) x [4i, 4i + 4);
//   output "offset":    1 x 2 x 64 x 80, the centre inside its cell, in cells, in [0, 1]:
//                       x_in = 4 (j + o_x), y_in = 4 (i + o_y);
//   output "log_sigma": 1 x 1 x 64 x 80, ln of the light's blob scale sigma in input pixels.
// Pixel centres at integer coordinates in both images, so u = (x_in + 1/2) / s_x - 1/2 (and v
// likewise), sigma_px = exp(log_sigma) / sqrt(s_x s_y).
//
// Per image: the heatmap's local maxima (3 x 3) at or above min_probability are the proposals.
// Each is refined on the full-resolution luma by the core centroid that the real-water detector
// uses (light_core_centroid.h: the core above 85 % of the local contrast, its weighted centroid
// and that centroid's covariance), when the core lies within max(refine_radius_sigmas sigma,
// min_refine_radius_px) of the proposal and does not run into a larger bright structure
// (touches_window); otherwise the proposal's own position stands (its core then taken as a disc
// of radius sigma there, for the checks below), with a covariance of
// (proposal_sigma_fraction sigma)^2, at least proposal_floor_px^2, per axis: the network's
// position is good to a fraction of the light's size, not to the core's tenths of a pixel. A
// detection whose halo (2 sigma) leaves the image is at_border, its covariance widened by
// (border_sigma_fraction sigma)^2 per axis, as the real-water detector does. score is the
// heatmap's probability; colour_excess the halo's colour against the image's median
// (light_candidate_checks.h), for the halo-colour learner. Proposals closer than
// max(min_separation_px, the larger radius) to a stronger one are the same light.
//
// Verification (verify, on by default): the network judges a proposal by what renders taught it,
// and a textured wall or a lit strut it never saw can look like a light to it. So each proposal
// must also pass the physical checks of the real-water detector that do not depend on its shape
// (light_candidate_checks.h, with checks' options): a core with contrast (peak - floor at least
// min_contrast_noise_sigmas x the image's pixel noise and min_contrast gray levels), not a
// ridge, a halo of the light's colour (checks.min_halo_excess) that is not just the colour of its
// surroundings. The shape checks (extent, elongation, flat top, peak drop) are the network's:
// they are what fails for a light pressed against a white funnel.
//
// Units: pixels (0, 0 the centre of the top-left pixel), gray levels. Detect() is const and
// thread-safe (the network's forward pass is serialised: OpenCV's Net is not re-entrant).
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/vision/light_candidate_checks.h"
#include "auvdock/vision/light_colour.h"
#include "auvdock/vision/light_core_centroid.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct LearnedLightDetectorOptions {
  std::string model_path;  // the ONNX file
  double min_probability = 0.4;
  LightColour colour = LightColour::kBlue;  // for colour_excess only
  bool deinterlace = false;  // keep the even field, rebuild odd rows (combing)
  LightCoreOptions core;
  double refine_radius_sigmas = 1.0;
  double min_refine_radius_px = 2.0;
  double proposal_sigma_fraction = 0.3;
  double proposal_floor_px = 0.7;
  double border_sigma_fraction = 0.5;
  double min_separation_px = 3.0;
  int max_detections = 64;
  bool verify = true;
  LightCandidateCheckOptions checks;  // its colour is set from `colour`
  double min_contrast = 20.0;
  double min_contrast_noise_sigmas = 5.0;
};

// Why a proposal was not kept ("" when it passes): the verification above.
std::string VerifyLightProposal(const LightCore& core, const LightCandidateEvidence& evidence,
                                double noise_sigma, bool has_colour,
                                const LearnedLightDetectorOptions& options);

class LearnedLightDetector {
 public:
  static constexpr int kInputWidth = 320;
  static constexpr int kInputHeight = 256;
  static constexpr int kStride = 4;

  // Loads the network. Throws std::runtime_error naming the file when it cannot be read or its
  // outputs do not have the contract's shapes, std::invalid_argument for options out of range.
  explicit LearnedLightDetector(const LearnedLightDetectorOptions& options);
  ~LearnedLightDetector();
  LearnedLightDetector(const LearnedLightDetector&) = delete;
  LearnedLightDetector& operator=(const LearnedLightDetector&) = delete;

  // Lights in an 8-bit BGR (CV_8UC3) or gray (CV_8UC1, given to the network as three equal
  // channels) image, by descending score. Throws std::invalid_argument for an empty image or
  // another type.
  std::vector<LightDetection> Detect(const cv::Mat& image) const;

  const LearnedLightDetectorOptions& options() const { return options_; }

 private:
  // The network's three outputs for a BGR image of any size (each 64 x 80, CV_32F).
  struct Maps {
    cv::Mat probability, offset_x, offset_y, log_sigma;
  };
  Maps Infer(const cv::Mat& bgr) const;

  struct Network;  // cv::dnn::Net, kept out of this header

  LearnedLightDetectorOptions options_;
  mutable std::mutex mutex_;
  std::unique_ptr<Network> net_;
};

}  // namespace auvdock
