// Blue LEDs drawn by the tests, independently of the simulator's renderer: a saturated white
// core (a disc, 4 x 4 supersampled, so that its centroid is the true centre) in a bright blue
// Gaussian halo, as close LEDs bloom in real pool footage (b - r of the halo ~100-170 gray
// levels 5-10 px from the core).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace auvdock::test {

struct Led {
  Eigen::Vector2d uv;
  double core_px;  // radius of the saturated core
  double halo_px;  // sigma of the blue halo
};

// Adds the LED to a CV_32FC3 BGR image (values 0-255 before clipping).
void AddLed(const Led& led, cv::Mat* image);

}  // namespace auvdock::test
