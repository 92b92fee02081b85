// PoseVerdict / NoLightOfTheDock (pose_verdict.h): a pose's verdict on the detections it did
// not identify, with views of the T dock from the default mono camera.
#include "auvdock/vision/pose_verdict.h"

#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

using Covariance6 = Eigen::Matrix<double, 6, 6>;

// Looking straight down at the dock from `distance_m`, turned by yaw about the optical axis.
Pose3 ViewFromAbove(double distance_m, double yaw) {
  Eigen::Matrix3d R_D_C;
  R_D_C << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  R_D_C = ExpSO3(Eigen::Vector3d(0.0, 0.0, yaw)) * R_D_C;
  const Pose3 T_D_C(Eigen::Quaterniond(R_D_C), -distance_m * R_D_C.col(2));
  return T_D_C.Inverse();
}

LightDetection At(const Eigen::Vector2d& uv) {
  LightDetection d;
  d.uv = uv;
  d.radius_px = 2.0;
  return d;
}

struct Scene {
  DockModel dock = test::LoadDock("t_shape.yaml");
  PinholeRadtanCamera camera = test::DefaultMonoCamera();
  Covariance6 covariance = 1e-8 * Covariance6::Identity();

  Eigen::Vector2d Pixel(const Pose3& T_C_D, int light) const {
    return *camera.Project(T_C_D * dock.lights[light].p_D);
  }
  PoseVerdict Verdict(const Pose3& T_C_D, int num_lights) const {
    return PoseVerdict(dock, camera, T_C_D, covariance, 0.2, num_lights, PoseVerdictOptions{});
  }
};

TEST(PoseVerdict, WhatLiesFarFromEveryPredictedLightIsNoLightOfTheDock) {
  const Scene scene;
  const Pose3 T_C_D = ViewFromAbove(4.0, 0.3);
  const PoseVerdict verdict = scene.Verdict(T_C_D, 6);
  ASSERT_TRUE(verdict.judges());
  const Eigen::Vector2d light = scene.Pixel(T_C_D, 2);
  EXPECT_TRUE(verdict.NearALight(At(light + Eigen::Vector2d(2.5, -1.0))));   // within the floor
  EXPECT_FALSE(verdict.NearALight(At(light + Eigen::Vector2d(0.0, 6.0))));  // beyond it
  // The gate grows with the prediction's uncertainty.
  const PoseVerdict loose(scene.dock, scene.camera, T_C_D, 1e-4 * Covariance6::Identity(), 0.2,
                          6, PoseVerdictOptions{});
  EXPECT_TRUE(loose.NearALight(At(light + Eigen::Vector2d(0.0, 6.0))));

  const std::vector<LightDetection> detections = {At(light + Eigen::Vector2d(1.0, 0.0)),
                                                  At(light + Eigen::Vector2d(40.0, 40.0)),
                                                  At(light + Eigen::Vector2d(-40.0, 30.0))};
  // The second is far and unidentified; the third is far but identified: it stays.
  const std::vector<bool> none = NoLightOfTheDock(detections, {-1, -1, 3}, verdict);
  EXPECT_EQ(none, std::vector<bool>({false, true, false}));
}

// A second detection beside a light that another detection is already identified as is not a
// light of the dock; beside a light not yet taken it stays.
TEST(PoseVerdict, ASecondDetectionOfATakenLightIsNoLightOfTheDock) {
  const Scene scene;
  const Pose3 T_C_D = ViewFromAbove(4.0, 0.3);
  const PoseVerdict verdict = scene.Verdict(T_C_D, 6);
  const Eigen::Vector2d light = scene.Pixel(T_C_D, 2);
  const LightDetection beside = At(light + Eigen::Vector2d(2.0, 2.0));
  EXPECT_TRUE(verdict.NearALight(beside));
  EXPECT_TRUE(verdict.NearALight(beside, {0, 1}));
  EXPECT_FALSE(verdict.NearALight(beside, {2}));
  const std::vector<LightDetection> detections = {At(light), beside};
  EXPECT_EQ(NoLightOfTheDock(detections, {2, -1}, verdict), std::vector<bool>({false, true}));
  EXPECT_EQ(NoLightOfTheDock(detections, {-1, -1}, verdict), std::vector<bool>({false, false}));
}

TEST(PoseVerdict, APoseThatIdentifiesFewOfTheLightsInViewDoesNotJudge) {
  const Scene scene;
  const Pose3 T_C_D = ViewFromAbove(4.0, 0.3);
  const PoseVerdict verdict = scene.Verdict(T_C_D, 4);  // 4 of 6 in view: below 3/4
  EXPECT_FALSE(verdict.judges());
  const std::vector<LightDetection> far = {At(scene.Pixel(T_C_D, 0) + Eigen::Vector2d(50, 50))};
  EXPECT_EQ(NoLightOfTheDock(far, {-1}, verdict), std::vector<bool>({false}));
}

}  // namespace
}  // namespace auvdock
