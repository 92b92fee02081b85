#include "auvdock/vision/saturated_disc.h"

#include <algorithm>
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
  EXPECT_FALSE(
      FindSaturatedDisc(LightImage({{Eigen::Vector2d(30, 240), 50.0}}), Eigen::Vector2d(30, 240)));
  // Two lights merged into one saturated region.
  const cv::Mat merged =
      LightImage({{Eigen::Vector2d(280, 240), 40.0}, {Eigen::Vector2d(345, 240), 40.0}});
  EXPECT_FALSE(FindSaturatedDisc(merged, Eigen::Vector2d(280, 240)));
  // The prediction far from any saturated pixel.
  EXPECT_FALSE(FindSaturatedDisc(LightImage({{Eigen::Vector2d(300, 240), 40.0}}),
                                 Eigen::Vector2d(400, 400)));
  // A small core: the blob detector's.
  EXPECT_FALSE(
      FindSaturatedDisc(LightImage({{Eigen::Vector2d(300, 240), 4.0}}), Eigen::Vector2d(300, 240)));
  // A ring (a lit rim), not a filled disc.
  cv::Mat ring(512, 640, CV_8UC3, cv::Scalar(40, 60, 20));
  cv::circle(ring, cv::Point(300, 240), 60, cv::Scalar(255, 255, 255), 12);
  EXPECT_FALSE(FindSaturatedDisc(ring, Eigen::Vector2d(360, 240)));
  // A grey image works the same way.
  cv::Mat grey;
  cv::cvtColor(LightImage({{Eigen::Vector2d(300, 240), 40.0}}), grey, cv::COLOR_BGR2GRAY);
  EXPECT_TRUE(FindSaturatedDisc(grey, Eigen::Vector2d(300, 240)).has_value());
}

TEST(SaturatedDiscTest, TheLightsCircleNotTheCentroidOfAnEggShapedPlateau) {
  // A reflection below the light merged into its plateau: a smaller saturated disc 70 px below a
  // 60 px one. The region's centroid lies ~13 px below the light; its circle is the light's.
  const Eigen::Vector2d light(320.4, 230.6);
  const Eigen::Vector2d reflection = light + Eigen::Vector2d(0.0, 70.0);
  cv::Mat image = LightImage({{light, 60.0}});
  cv::circle(
      image,
      cv::Point(static_cast<int>(reflection.x() * 16), static_cast<int>(reflection.y() * 16)),
      45 * 16, cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA, 4);
  cv::Mat least;
  cv::cvtColor(image, least, cv::COLOR_BGR2GRAY);
  const cv::Moments m = cv::moments(least >= 250, true);
  const Eigen::Vector2d centroid(m.m10 / m.m00, m.m01 / m.m00);
  ASSERT_GT((centroid - light).norm(), 10.0);
  const auto disc = FindSaturatedDisc(image, light);
  ASSERT_TRUE(disc.has_value());
  EXPECT_LT((disc->uv - light).norm(), 0.5);
  EXPECT_NEAR(disc->radius_px, 60.0, 1.0);
}

TEST(SaturatedDiscTest, FindsEveryWholeDiscOfAnImage) {
  cv::Mat image = LightImage({{Eigen::Vector2d(150.2, 200.7), 30.0},
                              {Eigen::Vector2d(420.6, 260.1), 50.0},
                              {Eigen::Vector2d(20.0, 480.0), 40.0}});  // cut by the border
  cv::rectangle(image, cv::Rect(300, 20, 200, 20), cv::Scalar(255, 255, 255), cv::FILLED);  // a bar
  cv::circle(image, cv::Point(560, 420), 40, cv::Scalar(255, 255, 255), 8);        // a ring
  cv::circle(image, cv::Point(60, 60), 3, cv::Scalar(255, 255, 255), cv::FILLED);  // a small core
  std::vector<LightDetection> discs = FindSaturatedDiscs(image);
  ASSERT_EQ(discs.size(), 2u);
  std::sort(discs.begin(), discs.end(),
            [](const LightDetection& a, const LightDetection& b) { return a.uv.x() < b.uv.x(); });
  EXPECT_LT((discs[0].uv - Eigen::Vector2d(150.2, 200.7)).norm(), 0.3);
  EXPECT_LT((discs[1].uv - Eigen::Vector2d(420.6, 260.1)).norm(), 0.3);
  EXPECT_NEAR(discs[1].radius_px, 50.0, 1.0);
}

}  // namespace
}  // namespace auvdock
