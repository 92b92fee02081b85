#include "auvdock/vision/prediction_association.h"

#include <vector>

#include <gtest/gtest.h>

namespace auvdock {
namespace {

LightDetection At(double u, double v, double radius_px = 2.0) {
  LightDetection d;
  d.uv = Eigen::Vector2d(u, v);
  d.radius_px = radius_px;
  return d;
}

PredictedLight Light(int id, double u, double v) {
  PredictedLight p;
  p.light_id = id;
  p.uv = Eigen::Vector2d(u, v);
  return p;
}

// Gate 4 px + 0.5 x the detection's radius (default options).
TEST(PredictionAssociationTest, LabelsADetectionThatOnlyOneLightCanExplain) {
  const std::vector<PredictedLight> lights = {Light(3, 100, 100), Light(5, 300, 100)};
  const std::vector<int> ids =
      AssociateByPrediction({At(102, 101), At(200, 100), At(306, 100)}, lights);
  ASSERT_EQ(ids.size(), 3u);
  EXPECT_EQ(ids[0], 3);   // 2.2 px from light 3
  EXPECT_EQ(ids[1], -1);  // far from both
  EXPECT_EQ(ids[2], -1);  // 6 px: beyond the 5 px gate of a radius-2 blob
}

TEST(PredictionAssociationTest, AGateGrowsWithTheBlobsOwnSize) {
  const std::vector<PredictedLight> lights = {Light(3, 320, 256), Light(4, 120, 256)};
  // A glow of radius 80 px whose centroid is 20 px off the prediction: gate 44 px.
  EXPECT_EQ(AssociateByPrediction({At(338, 265, 80.0)}, lights)[0], 3);
  EXPECT_EQ(AssociateByPrediction({At(338, 265, 20.0)}, lights)[0], -1);
}

// A glow that reaches another light's place (merged glows) has its centre pulled towards it.
TEST(PredictionAssociationTest, ABlobThatCoversAnotherLightIsNotLabelled) {
  const std::vector<PredictedLight> lights = {Light(4, 320, 256), Light(3, 361, 256)};
  EXPECT_EQ(AssociateByPrediction({At(321, 256, 30.0)}, lights)[0], -1);  // light 3 at 1.4 r
  EXPECT_EQ(AssociateByPrediction({At(321, 256, 15.0)}, lights)[0], 4);   // at 2.7 r
}

TEST(PredictionAssociationTest, NeverGuessesBetweenTwoCandidates) {
  // Two lights nearly equally near one detection.
  const std::vector<PredictedLight> close = {Light(1, 100, 100), Light(2, 106, 100)};
  EXPECT_EQ(AssociateByPrediction({At(102, 100)}, close)[0], -1);
  // Two detections near one light: neither is labelled.
  const std::vector<PredictedLight> one = {Light(1, 100, 100)};
  const std::vector<int> ids = AssociateByPrediction({At(101, 100), At(99, 101)}, one);
  EXPECT_EQ(ids[0], -1);
  EXPECT_EQ(ids[1], -1);
  // No prediction, no label.
  EXPECT_EQ(AssociateByPrediction({At(101, 100)}, {})[0], -1);
}

}  // namespace
}  // namespace auvdock
