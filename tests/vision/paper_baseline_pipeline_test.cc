#include "auvdock/vision/paper_baseline_pipeline.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/dock_views.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

// Perfect detections of every dock light in view of `camera` at body pose T_D_B, with the given
// radius per light id (default 10 px), in light-id order.
std::vector<LightDetection> ProjectLights(const CameraCalibration& camera, const DockModel& dock,
                                          const Pose3& T_D_B,
                                          const std::map<int, double>& radius_px = {}) {
  const Pose3 T_C_D = (T_D_B * camera.T_B_C).Inverse();
  std::vector<LightDetection> detections;
  for (const DockLight& light : dock.lights) {
    const auto uv = camera.intrinsics.Project(T_C_D * light.p_D);
    if (!uv || !camera.intrinsics.InImage(*uv)) continue;
    LightDetection d;
    d.uv = *uv;
    const auto r = radius_px.find(light.id);
    d.radius_px = r == radius_px.end() ? 10.0 : r->second;
    d.peak = 200.0;
    d.score = 0.9;
    detections.push_back(d);
  }
  return detections;
}

// The light id each detection is the projection of (nearest within 1 px), -1 if none.
std::vector<int> TrueIds(const std::vector<LightDetection>& detections,
                         const CameraCalibration& camera, const DockModel& dock,
                         const Pose3& T_D_B) {
  const Pose3 T_C_D = (T_D_B * camera.T_B_C).Inverse();
  std::vector<int> ids;
  for (const LightDetection& d : detections) {
    int id = -1;
    for (const DockLight& light : dock.lights) {
      const auto uv = camera.intrinsics.Project(T_C_D * light.p_D);
      if (uv && (*uv - d.uv).norm() < 1.0) id = light.id;
    }
    ids.push_back(id);
  }
  return ids;
}

// The default scenario 6 s into the run (6.6 m from the dock): the crossbar (lights 3, 4, 5)
// lies nearly along an epipolar line of the stereo pair, 45 px apart. The radii are those the
// detector measured on that frame when the lit deck merged into the blobs: unrelated between
// the two images, so that the radius gate rejects some true pairs (5: 12.5 vs 20.8 px; 3: 18.8
// vs 9.1 px) and accepts shifted ones. Left-right matching then paired the left image's lights 4
// and 5 with the right image's 3 and 4 (same order along the line, a depth of ~3 m instead of
// ~7 m) and the stereo pose came out ~10 m off.
TEST(PaperBaselinePipelineTest, ALoneStereoCameraIsAWarningNotSilence) {
  const Scenario scenario = test::DefaultScenario();
  Calibration calibration = MakeCalibration(scenario);
  EXPECT_TRUE(PaperBaselinePipeline(calibration, scenario.dock).warnings().empty());
  calibration.cameras.erase(
      std::remove_if(calibration.cameras.begin(), calibration.cameras.end(),
                     [](const CameraCalibration& c) { return c.role != CameraRole::kStereoLeft; }),
      calibration.cameras.end());
  const PaperBaselinePipeline pipeline(calibration, scenario.dock);
  ASSERT_EQ(pipeline.warnings().size(), 1u);
  EXPECT_NE(pipeline.warnings()[0].find(calibration.cameras[0].name + " has role stereo_left"),
            std::string::npos)
      << pipeline.warnings()[0];
}

TEST(PaperBaselinePipelineTest, CrossbarAlongTheEpipolarLineKeepsItsIdentities) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  const Pose3 T_D_B = trajectory.At(6.0).T_D_B;
  PaperBaselinePipeline pipeline(calibration, scenario.dock);
  const CameraCalibration& left = *pipeline.left_camera();
  const CameraCalibration& right = *pipeline.right_camera();

  const std::vector<LightDetection> left_detections =
      ProjectLights(left, scenario.dock, T_D_B,
                    {{0, 12.6}, {1, 25.2}, {2, 20.0}, {3, 18.8}, {4, 8.1}, {5, 12.5}});
  const std::vector<LightDetection> right_detections =
      ProjectLights(right, scenario.dock, T_D_B,
                    {{0, 11.2}, {1, 10.6}, {2, 12.9}, {3, 9.1}, {4, 9.9}, {5, 20.8}});
  ASSERT_EQ(left_detections.size(), 6u);
  ASSERT_EQ(right_detections.size(), 6u);

  const BaselineFrame frame =
      pipeline.ProcessDetections(6'000'000'000, left_detections, right_detections, std::nullopt);
  ASSERT_EQ(frame.left.status, MatchStatus::kOk);
  const std::vector<int> truth_left = TrueIds(frame.left.detections, left, scenario.dock, T_D_B);
  const std::vector<int> truth_right = TrueIds(frame.right.detections, right, scenario.dock, T_D_B);
  for (std::size_t i = 0; i < truth_left.size(); ++i) {
    if (frame.left.light_ids[i] >= 0) {
      EXPECT_EQ(frame.left.light_ids[i], truth_left[i]) << "left detection " << i;
    }
  }
  for (std::size_t i = 0; i < truth_right.size(); ++i) {
    if (frame.right.light_ids[i] >= 0) {
      EXPECT_EQ(frame.right.light_ids[i], truth_right[i]) << "right detection " << i;
    }
  }
  // Noise-free detections: the identities are all recoverable, and the pose is exact.
  ASSERT_TRUE(frame.T_D_B_stereo.has_value()) << frame.reason;
  EXPECT_EQ(frame.n_stereo_lights, 6);
  EXPECT_LT((frame.T_D_B_stereo->p - T_D_B.p).norm(), 1e-3);
  EXPECT_LT(frame.stereo_reprojection_px, 0.05);
}

// Without a pose from the identified image (the paper's omnidirectional matcher gives labels
// only), the right image's identities come from left-right matching alone, which the radii of
// the frame above mislead; the stereo pose that results does not reproject onto its lights and
// is refused, and the transferred identities are withdrawn.
TEST(PaperBaselinePipelineTest, RefusesAStereoPoseThatDoesNotReproject) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  const Pose3 T_D_B = trajectory.At(6.0).T_D_B;
  PaperBaselineOptions options;
  options.matcher = BaselineMatcher::kOmnidirectional;
  PaperBaselinePipeline pipeline(calibration, scenario.dock, options);
  const CameraCalibration& left = *pipeline.left_camera();
  const CameraCalibration& right = *pipeline.right_camera();

  const BaselineFrame frame = pipeline.ProcessDetections(
      6'000'000'000,
      ProjectLights(left, scenario.dock, T_D_B,
                    {{0, 12.6}, {1, 25.2}, {2, 20.0}, {3, 18.8}, {4, 8.1}, {5, 12.5}}),
      ProjectLights(right, scenario.dock, T_D_B,
                    {{0, 11.2}, {1, 10.6}, {2, 12.9}, {3, 9.1}, {4, 9.9}, {5, 20.8}}),
      std::nullopt);
  ASSERT_EQ(frame.left.status, MatchStatus::kOk) << frame.left.reason;
  const std::vector<int> truth_left = TrueIds(frame.left.detections, left, scenario.dock, T_D_B);
  for (std::size_t i = 0; i < truth_left.size(); ++i) {
    ASSERT_EQ(frame.left.light_ids[i], truth_left[i]) << "the matcher itself is right";
  }
  EXPECT_FALSE(frame.T_D_B_stereo.has_value());
  EXPECT_NE(frame.reason.find("reprojects"), std::string::npos) << frame.reason;
  for (int id : frame.right.light_ids) EXPECT_EQ(id, -1);
}


// The default scenario at t = 27.5 s: the mono camera sees the stem lights 1, 2, 4 and the bar
// light 3 from 2.5 m (pixels: the light detector's centroids on the rendered frame). The
// hypothesise-and-verify matcher refuses the set (all lights but one collinear), tracking labels
// it, and of the two PnP minima that fit these pixels equally well the flipped one (21 deg of
// roll, 0.9 m across the dock) has the lower cost; it used to be reported. The prediction from
// the previous frame must choose the true one.
TEST(PaperBaselinePipelineTest, MonoPoseOfAPlanarTwinIsChosenByThePrediction) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  PaperBaselinePipeline pipeline(calibration, scenario.dock);
  const CameraCalibration& mono = *pipeline.mono_camera();

  // t = 27.4 s: five lights, identified from scratch; the pose seeds the tracking.
  const Pose3 T_D_B_previous = trajectory.At(27.4).T_D_B;
  const BaselineFrame previous =
      pipeline.ProcessDetections(27'400'000'000, std::nullopt, std::nullopt,
                                 ProjectLights(mono, scenario.dock, T_D_B_previous));
  ASSERT_TRUE(previous.T_D_B_mono.has_value()) << previous.reason;

  std::vector<LightDetection> detections(4);
  detections[0].uv = {344.6086647053071, 267.5940199749991};    // light 4
  detections[1].uv = {222.5568302291267, 268.2067541410845};    // light 3
  detections[2].uv = {345.2474492103146, 369.34529842722975};   // light 2
  detections[3].uv = {346.32068341040815, 470.40839314548697};  // light 1
  for (LightDetection& d : detections) {
    d.radius_px = 23.0;
    d.peak = 200.0;
    d.score = 0.74;
  }
  const BaselineFrame frame =
      pipeline.ProcessDetections(27'500'000'000, std::nullopt, std::nullopt, detections);
  EXPECT_TRUE(frame.mono.tracked);
  EXPECT_EQ(frame.mono.light_ids, (std::vector<int>{4, 3, 2, 1}));
  ASSERT_TRUE(frame.T_D_B_mono.has_value()) << frame.reason;
  const Pose3 T_D_B = trajectory.At(27.5).T_D_B;
  EXPECT_LT((frame.T_D_B_mono->p - T_D_B.p).norm(), 0.05);
  EXPECT_LT(RotationAngleBetween(frame.T_D_B_mono->q, T_D_B.q), 0.02);
}

// The ring of 8 (turns of 90 degrees about gravity) without an approach side: the first pose is
// one of four rivals chosen by nothing, and every frame that tracks it stays flagged; an
// acoustic fix of the transponder at the first frame picks the true copy.
TEST(PaperBaselinePipelineTest, AnUnresolvedSymmetricChoiceIsFlaggedWhileTrackedAndAFixResolvesIt) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  DockModel ring = test::LoadDock("ring_8.yaml");
  ring.approach_direction_D = Eigen::Vector3d::Zero();
  const auto frames = [&](PaperBaselinePipeline& pipeline) {
    std::vector<BaselineFrame> out;
    for (const double t : {20.0, 20.1, 20.2}) {
      out.push_back(pipeline.ProcessDetections(
          static_cast<int64_t>(t * 1e9), std::nullopt, std::nullopt,
          ProjectLights(*pipeline.mono_camera(), ring, trajectory.At(t).T_D_B)));
    }
    return out;
  };
  PaperBaselinePipeline alone(calibration, ring);
  const std::vector<BaselineFrame> unresolved = frames(alone);
  ASSERT_TRUE(unresolved[0].T_D_B.has_value()) << unresolved[0].reason;
  EXPECT_TRUE(unresolved[0].mono.symmetry_unresolved) << unresolved[0].mono.symmetry;
  for (const BaselineFrame& f : unresolved) {
    ASSERT_TRUE(f.T_D_B.has_value()) << f.reason;
    EXPECT_TRUE(f.symmetry_unresolved) << f.mono.symmetry;
  }

  PaperBaselinePipeline with_fix(calibration, ring);
  const Pose3 T_B_S(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, -0.2));
  with_fix.SetPositionFix(20'000'000'000, trajectory.At(20.0).T_D_B * T_B_S.p, 0.05, T_B_S);
  const std::vector<BaselineFrame> resolved = frames(with_fix);
  for (size_t k = 0; k < resolved.size(); ++k) {
    ASSERT_TRUE(resolved[k].T_D_B.has_value()) << resolved[k].reason;
    EXPECT_FALSE(resolved[k].symmetry_unresolved) << resolved[k].mono.symmetry;
    const Pose3 truth = trajectory.At(20.0 + 0.1 * k).T_D_B;
    EXPECT_LT((resolved[k].T_D_B->p - truth.p).norm(), 0.05);
  }
  EXPECT_NE(resolved[0].mono.symmetry.find("acoustic fix"), std::string::npos)
      << resolved[0].mono.symmetry;
}

// The end of a landing: the mono camera sees two lights, too few for any pose. With a fresh
// prediction from the estimator (a light was identified 0.1 s before) step 7 labels them; without
// a prediction, or when the last identified light is older than estimate_max_age_s, it does not.
TEST(PaperBaselinePipelineTest, TheEstimateIdentifiesTheFewLightsOfALanding) {
  const Scenario scenario = test::DefaultScenario();
  const Calibration calibration = MakeCalibration(scenario);
  const DockingTrajectory trajectory(scenario.trajectory);
  const auto two_lights = [&](const CameraCalibration& mono, const Pose3& T_D_B) {
    std::vector<LightDetection> all = ProjectLights(mono, scenario.dock, T_D_B);
    const std::vector<int> ids = TrueIds(all, mono, scenario.dock, T_D_B);
    std::vector<LightDetection> two;
    std::vector<int> two_ids;
    for (size_t i = 0; i < all.size() && two.size() < 2; ++i) {
      two.push_back(all[i]);
      two_ids.push_back(ids[i]);
    }
    return std::make_pair(two, two_ids);
  };
  for (const double gap_s : {0.1, 0.7}) {
    PaperBaselinePipeline pipeline(calibration, scenario.dock);
    const CameraCalibration& mono = *pipeline.mono_camera();
    const BaselineFrame seen = pipeline.ProcessDetections(
        27'400'000'000, std::nullopt, std::nullopt,
        ProjectLights(mono, scenario.dock, trajectory.At(27.4).T_D_B));
    ASSERT_TRUE(seen.T_D_B.has_value()) << seen.reason;
    const double t = 27.4 + gap_s;
    const Pose3 T_D_B = trajectory.At(t).T_D_B;
    const auto [detections, true_ids] = two_lights(mono, T_D_B);
    ASSERT_EQ(detections.size(), 2u);
    const int64_t t_ns = static_cast<int64_t>(std::llround(t * 1e9));
    // A prediction 3 mm and 0.1 degrees off.
    const Pose3 predicted(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.0017, Eigen::Vector3d::UnitZ())) * T_D_B.q,
        T_D_B.p + Eigen::Vector3d(0.003, -0.002, 0.001));
    const BaselineFrame frame =
        pipeline.ProcessDetections(t_ns, std::nullopt, std::nullopt, detections, predicted);
    EXPECT_FALSE(frame.T_D_B.has_value());
    if (gap_s < 0.5) {
      EXPECT_TRUE(frame.by_estimate);
      EXPECT_EQ(frame.mono.light_ids, true_ids);
      EXPECT_EQ(frame.mono.by_estimate, 2);
    } else {
      EXPECT_FALSE(frame.by_estimate);
      EXPECT_EQ(frame.mono.num_identified(), 0);
    }
  }
  // No prediction: nothing to label by.
  PaperBaselinePipeline pipeline(calibration, scenario.dock);
  const CameraCalibration& mono = *pipeline.mono_camera();
  pipeline.ProcessDetections(27'400'000'000, std::nullopt, std::nullopt,
                             ProjectLights(mono, scenario.dock, trajectory.At(27.4).T_D_B));
  const BaselineFrame frame = pipeline.ProcessDetections(
      27'500'000'000, std::nullopt, std::nullopt, two_lights(mono, trajectory.At(27.5).T_D_B).first);
  EXPECT_EQ(frame.mono.num_identified(), 0);
}

}  // namespace
}  // namespace auvdock
