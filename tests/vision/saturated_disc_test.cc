#include "auvdock/vision/saturated_disc.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

// A cyan glow (saturated in green and blue, not in red) around a white saturated disc, as a
// light under the camera looks; centres in pixels, sub-pixel by drawing at 16x.
cv::Mat LightImage(const std::vector<std::pair<Eigen::Vector2d, double>>& discs) {
  cv::Mat image(512, 640, CV_8UC3, cv::Scalar(40, 60, 20));
  for (const auto& [c, r] : discs) {
    const cv::Point centre(static_cast<int>(std::lround(c.x() * 16)),
                           static_cast<int>(std::lround(c.y() * 16)));
    cv::circle(image, centre, static_cast<int>(std::lround(1.6 * r * 16)),
               cv::Scalar(255, 255, 120), cv::FILLED, cv::LINE_AA, 4);
  }
  for (const auto& [c, r] : discs) {
    const cv::Point centre(static_cast<int>(std::lround(c.x() * 16)),
                           static_cast<int>(std::lround(c.y() * 16)));
    cv::circle(image, centre, static_cast<int>(std::lround(r * 16)), cv::Scalar(255, 255, 255),
               cv::FILLED, cv::LINE_AA, 4);
  }
  return image;
}

TEST(SaturatedDiscTest, FindsTheCentreOfALargeSaturatedDisc) {
  const Eigen::Vector2d centre(300.3, 240.7);
  const cv::Mat image = LightImage({{centre, 60.0}});
  // The prediction 5 px off, inside the disc.
  const auto disc = FindSaturatedDisc(image, centre + Eigen::Vector2d(4.0, -3.0));
  ASSERT_TRUE(disc.has_value());
  EXPECT_LT((disc->uv - centre).norm(), 0.3);
  EXPECT_NEAR(disc->radius_px, 60.0, 1.0);
  // Its centroid sigma grows with the disc: 0.2 x 60 + 0.5 px.
  EXPECT_NEAR(std::sqrt(disc->covariance(0, 0)), 12.5, 0.3);
}

TEST(SaturatedDiscTest, RefusesWhatIsNotOneWholeRoundDisc) {
  // Cut by the image border.
  EXPECT_FALSE(FindSaturatedDisc(LightImage({{Eigen::Vector2d(30, 240), 50.0}}),
                                 Eigen::Vector2d(30, 240)));
  // Two lights merged into one saturated region.
  const cv::Mat merged =
      LightImage({{Eigen::Vector2d(280, 240), 40.0}, {Eigen::Vector2d(345, 240), 40.0}});
  EXPECT_FALSE(FindSaturatedDisc(merged, Eigen::Vector2d(280, 240)));
  // The prediction far from any saturated pixel.
  EXPECT_FALSE(FindSaturatedDisc(LightImage({{Eigen::Vector2d(300, 240), 40.0}}),
                                 Eigen::Vector2d(400, 400)));
  // A small core: the blob detector's.
  EXPECT_FALSE(FindSaturatedDisc(LightImage({{Eigen::Vector2d(300, 240), 4.0}}),
                                 Eigen::Vector2d(300, 240)));
  // A ring (a lit rim), not a filled disc.
  cv::Mat ring(512, 640, CV_8UC3, cv::Scalar(40, 60, 20));
  cv::circle(ring, cv::Point(300, 240), 60, cv::Scalar(255, 255, 255), 12);
  EXPECT_FALSE(FindSaturatedDisc(ring, Eigen::Vector2d(360, 240)));
  // A grey image works the same way.
  cv::Mat grey;
  cv::cvtColor(LightImage({{Eigen::Vector2d(300, 240), 40.0}}), grey, cv::COLOR_BGR2GRAY);
  EXPECT_TRUE(FindSaturatedDisc(grey, Eigen::Vector2d(300, 240)).has_value());
}

}  // namespace
}  // namespace auvdock
