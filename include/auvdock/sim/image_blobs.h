// Drawing primitives of the renderer: a light's blob and its bloom smear, added to a CV_32FC3
// BGR image of gray levels (before clipping), each exactly symmetric about its centre so that a
// drawn blob's intensity centroid is its centre.
// Frames: image pixels, (0, 0) the centre of the top-left pixel.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace auvdock {

// Adds amplitude_bgr * exp(-|x - uv|^2 / (2 sigma^2)). The support is a disc around the exact
// centre, wide enough that the cut-off tail is below a quarter gray level (and at least
// 4 sigma), so the drawn blob stays symmetric about uv.
void AddGaussianBlob(const Eigen::Vector2d& uv, double sigma, const Eigen::Vector3d& amplitude_bgr,
                     cv::Mat* image);

// Adds amplitude_bgr * exp(-du^2 / (2 sigma^2)) * exp(-|dv| / (40 sigma)) over whole columns
// around uv: a saturated light's bloom smear, symmetric about the light.
void AddVerticalSmear(const Eigen::Vector2d& uv, double sigma, const Eigen::Vector3d& amplitude_bgr,
                      cv::Mat* image);

}  // namespace auvdock
