#include "auvdock/estimator/vision_frame_builder.h"

#include <gtest/gtest.h>

#include "auvdock/sim/scenario.h"
#include "auvdock/vision/stereo_triangulation.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

// The dock's first light 6 m in front of the stereo-left camera, identified in both images and in
// the mono image with centroid sigmas of its own.
struct IdentifiedLight {
  IdentifiedLight() {
    left = calibration.FindCameraByRole(CameraRole::kStereoLeft);
    right = calibration.FindCameraByRole(CameraRole::kStereoRight);
    mono = calibration.FindCameraByRole(CameraRole::kMono);
  }
  // The light's detection in `camera` with an isotropic centroid sigma.
  CameraObservation Seen(const CameraCalibration& camera, double sigma_px) const {
    const Eigen::Vector3d p_B = left->T_B_C * p_S;
    CameraObservation observation;
    LightDetection detection;
    detection.uv = *camera.intrinsics.Project(camera.T_B_C.Inverse() * p_B);
    detection.covariance = sigma_px * sigma_px * Eigen::Matrix2d::Identity();
    observation.detections.push_back(detection);
    observation.light_ids.push_back(light_id);
    return observation;
  }
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const CameraCalibration* left = nullptr;
  const CameraCalibration* right = nullptr;
  const CameraCalibration* mono = nullptr;
  const int light_id = scenario.dock.lights.front().id;
  const Eigen::Vector3d p_S = Eigen::Vector3d(0.2, -0.1, 6.0);
};

// A pair whose right detection is a saturated light's (3 times the camera's sigma) is
// triangulated at that sigma: the covariance 9 times the camera's; a pair with the detector's
// sigmas below the camera's stays at the camera's. The mono pixel likewise.
TEST(VisionFrameBuilderTest, EachPairAndPixelAtTheLargerOfTheCamerasAndItsOwnSigma) {
  IdentifiedLight light;
  ASSERT_NE(light.left, nullptr);
  ASSERT_NE(light.right, nullptr);
  ASSERT_NE(light.mono, nullptr);
  const double camera_sigma = light.left->pixel_noise_px;
  const Eigen::Matrix3d at_camera_sigma =
      TriangulateLinear(light.Seen(*light.left, 0.0).detections[0].uv,
                        light.Seen(*light.right, 0.0).detections[0].uv, *light.left, *light.right,
                        camera_sigma)
          .covariance;
  for (const double right_sigma : {0.5 * camera_sigma, 3.0 * camera_sigma}) {
    BaselineFrame frame;
    frame.left = light.Seen(*light.left, 0.5 * camera_sigma);
    frame.right = light.Seen(*light.right, right_sigma);
    frame.mono = light.Seen(*light.mono, right_sigma);
    const VisionFrame built = MakeVisionFrame(frame, light.left, light.right, light.mono);
    ASSERT_EQ(built.stereo.size(), 1u);
    ASSERT_EQ(built.mono.size(), 1u);
    const double expected = std::max(camera_sigma, right_sigma);
    EXPECT_DOUBLE_EQ(built.stereo[0].sigma_px, expected);
    const double ratio = expected * expected / (camera_sigma * camera_sigma);
    EXPECT_TRUE(built.stereo[0].covariance.isApprox(ratio * at_camera_sigma, 1e-9))
        << built.stereo[0].covariance << "\n" << at_camera_sigma;
    EXPECT_DOUBLE_EQ(built.mono[0].sigma_px, std::max(light.mono->pixel_noise_px, right_sigma));
  }
}

}  // namespace
}  // namespace auvdock
