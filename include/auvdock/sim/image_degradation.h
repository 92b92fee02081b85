// What the camera and the video chain do to the rendered scene, per frame: optical blur
// (defocus and motion), interlacing, the camera's colour cast and JPEG compression. Part of the
// renderer's domain randomisation (render_look.h); none of it is applied with the default look.
//
// Each effect keeps the ground truth of a light where it was, so that a detector's error on a
// degraded image is its own:
//   - motion blur is a line kernel centred on the pixel (length L, angle a), defocus a Gaussian:
//     both symmetric, so an unsaturated blob's intensity centroid does not move;
//   - interlacing: the two fields are half a frame apart; the even rows are sampled displaced by
//     +d/2 and the odd rows by -d/2 (bilinear), so the mean of the two fields is the frame's
//     mid-exposure image, which is where the ground truth is;
//   - the colour cast is a gain per channel (B, G, R);
//   - JPEG is a round trip through OpenCV's encoder at the drawn quality.
// Frames: image pixels, (0, 0) the centre of the top-left pixel. Images: CV_32FC3 gray levels
// before quantisation, CV_8UC3 for JPEG.
#pragma once

#include <random>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "auvdock/sim/render_look.h"

namespace auvdock {

// The per-frame draws of a look.
struct FrameDegradation {
  double motion_blur_px = 0.0;
  double motion_blur_angle_rad = 0.0;
  Eigen::Vector2d field_offset_px = Eigen::Vector2d::Zero();  // second field minus first
  int jpeg_quality = 0;                                       // 0: no compression
};

// Draws nothing (and leaves rng alone) for the default look.
FrameDegradation DrawFrameDegradation(const RenderLook& look, std::mt19937_64& rng);

// Defocus, motion blur and interlacing of a CV_32FC3 image, in place.
void ApplyOpticsAndFields(const RenderLook& look, const FrameDegradation& frame, cv::Mat* image);

// Multiplies each channel of a CV_32FC3 image by the look's colour cast, in place.
void ApplyColourCast(const RenderLook& look, cv::Mat* image);

// A CV_8UC3 image after a JPEG round trip at frame.jpeg_quality (unchanged if 0).
cv::Mat ApplyJpeg(const FrameDegradation& frame, const cv::Mat& image);

// The normalised line kernel of motion blur (odd size), exposed for the tests.
cv::Mat MotionBlurKernel(double length_px, double angle_rad);

}  // namespace auvdock
