// PoseFromIdentifiedLights (identified_light_pose.h): the pose of lights identified by a walk,
// from the walk's pose; a glint taken for a light is left out; refused with fewer than 4 lights,
// with 4 that fit no pose, and where PnP lands far from the walk's pose.
#include "auvdock/vision/identified_light_pose.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

class IdentifiedLightPoseTest : public ::testing::Test {
 protected:
  IdentifiedLightPoseTest()
      : dock_(test::LoadDock("t_shape.yaml")),
        truth_(test::ViewFromElevation(dock_, 4.0, 55.0 * M_PI / 180.0, 0.3)) {
    camera_.name = "cam2";
    camera_.intrinsics = test::DefaultMonoCamera();
    camera_.pixel_noise_px = 0.3;
    std::mt19937_64 rng(3);
    std::normal_distribution<double> noise(0.0, 0.3);
    for (const DockLight& light : dock_.lights) {
      LightDetection d;
      d.uv =
          *camera_.intrinsics.Project(truth_ * light.p_D) + Eigen::Vector2d(noise(rng), noise(rng));
      d.radius_px = 3.0;
      detections_.push_back(d);
      ids_.push_back(light.id);
    }
  }

  // The truth turned by angle_deg about the camera's x axis (the walk's pose, a little off).
  Pose3 Start(double angle_deg) const {
    return Pose3(ExpQuaternion(Eigen::Vector3d(angle_deg * M_PI / 180.0, 0.0, 0.0)) * truth_.q,
                 truth_.p);
  }

  DockModel dock_;
  Pose3 truth_;
  CameraCalibration camera_;
  std::vector<LightDetection> detections_;
  std::vector<int> ids_;
};

TEST_F(IdentifiedLightPoseTest, ThePoseOfTheIdentifiedLights) {
  const IdentifiedLightPose pose =
      PoseFromIdentifiedLights(camera_, dock_, detections_, ids_, Start(3.0));
  ASSERT_TRUE(pose.T_C_D) << pose.reason;
  EXPECT_EQ(pose.num_lights, static_cast<int>(dock_.lights.size()));
  EXPECT_LT((pose.T_C_D->p - truth_.p).norm(), 0.05);
  EXPECT_LT(RotationAngleBetween(pose.T_C_D->q, truth_.q), 0.5 * M_PI / 180.0);
  EXPECT_LT(pose.rms_px, 1.0);
  EXPECT_GT(pose.covariance_local.trace(), 0.0);
  EXPECT_TRUE(pose.reason.empty());
  EXPECT_EQ(pose.light_ids, ids_);
}

TEST_F(IdentifiedLightPoseTest, FewerThanFourLightsGiveNoPose) {
  std::vector<int> ids = ids_;
  for (size_t i = 3; i < ids.size(); ++i) ids[i] = -1;
  const IdentifiedLightPose pose =
      PoseFromIdentifiedLights(camera_, dock_, detections_, ids, Start(1.0));
  EXPECT_FALSE(pose.T_C_D);
  EXPECT_EQ(pose.reason, "3 identified lights (need 4)");
}

TEST_F(IdentifiedLightPoseTest, AGlintTakenForALightIsLeftOut) {
  // Light 3's own detection left unidentified, and a glint 6 px from it identified as light 3.
  std::vector<LightDetection> detections = detections_;
  std::vector<int> ids = ids_;
  LightDetection glint = detections_[3];
  glint.uv += Eigen::Vector2d(6.0, -2.0);
  detections.push_back(glint);
  ids.push_back(3);
  ids[3] = -1;
  const IdentifiedLightPose pose =
      PoseFromIdentifiedLights(camera_, dock_, detections, ids, Start(1.0));
  ASSERT_TRUE(pose.T_C_D) << pose.reason;
  EXPECT_EQ(pose.num_lights, 5);
  std::vector<int> expected = ids;
  expected.back() = -1;
  EXPECT_EQ(pose.light_ids, expected);
  EXPECT_LT((pose.T_C_D->p - truth_.p).norm(), 0.05);
}

TEST_F(IdentifiedLightPoseTest, FourLightsThatFitNoPoseGiveNone) {
  // Four lights, one of them the glint: nothing to leave out.
  std::vector<LightDetection> detections(detections_.begin(), detections_.begin() + 4);
  detections[3] = detections_[2];
  detections[3].uv += Eigen::Vector2d(0.0, 8.0);
  const std::vector<int> ids(ids_.begin(), ids_.begin() + 4);
  const IdentifiedLightPose pose =
      PoseFromIdentifiedLights(camera_, dock_, detections, ids, Start(1.0));
  EXPECT_FALSE(pose.T_C_D);
  EXPECT_NE(pose.reason.find("not consistent with one pose"), std::string::npos) << pose.reason;
}

TEST_F(IdentifiedLightPoseTest, APoseFarFromTheWalksIsNotTheOneItsLabelsDescribe) {
  const IdentifiedLightPose pose =
      PoseFromIdentifiedLights(camera_, dock_, detections_, ids_, Start(25.0));
  EXPECT_FALSE(pose.T_C_D);
  EXPECT_NE(pose.reason.find("deg from the walk's"), std::string::npos) << pose.reason;
}

}  // namespace
}  // namespace auvdock
