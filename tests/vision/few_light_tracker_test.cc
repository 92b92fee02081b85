// FewLightTracker and BridgeFramesWithoutPose on a camera moving at a constant rate over the T
// dock: two of its lights and a speck seen after (or before) a run of posed frames.
#include "auvdock/vision/few_light_tracker.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/vision/two_way_light_bridge.h"
#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;

class FewLightTrackerTest : public ::testing::Test {
 protected:
  FewLightTrackerTest()
      : camera_(test::DefaultMonoCamera()),
        dock_(test::LoadDock("t_shape.yaml")),
        start_(test::ViewFromElevation(dock_, 4.0, 60.0 * M_PI / 180.0, 0.0)) {}

  // The camera at frame k: R_k = Exp(k w) R_0, p_k = p_0 + k v (the tracker's own model), plus a
  // sudden turn of jerk_rad about the camera's y axis (across the T's stem in the image) from
  // frame jerk_from on.
  Pose3 Truth(int k, int jerk_from = 1 << 30, double jerk_rad = 0.0) const {
    const Eigen::Vector3d w(0.002, -0.001, 0.003), v(0.01, 0.004, -0.02);
    const Eigen::Vector3d jerk(0.0, k >= jerk_from ? jerk_rad : 0.0, 0.0);
    return Pose3(ExpQuaternion(jerk) * ExpQuaternion(k * w) * start_.q,
                 start_.p + k * v);
  }

  Eigen::Vector2d Project(const Pose3& T_C_D, int light_id) const {
    for (const DockLight& light : dock_.lights) {
      if (light.id == light_id) return *camera_.Project(T_C_D * light.p_D);
    }
    ADD_FAILURE() << "no light " << light_id;
    return Eigen::Vector2d::Zero();
  }

  LightDetection Detection(const Eigen::Vector2d& uv) {
    LightDetection d;
    d.uv = uv + Eigen::Vector2d(noise_(rng_), noise_(rng_));
    d.radius_px = 3.0;
    d.score = 1.0;
    return d;
  }

  // Lights 0 and 1 (the T's stem) and a speck 90 px right of and 60 px below light 0.
  std::vector<LightDetection> TwoLightsAndASpeck(const Pose3& T_C_D) {
    return {Detection(Project(T_C_D, 0)), Detection(Project(T_C_D, 1)),
            Detection(Project(T_C_D, 0) + Eigen::Vector2d(90.0, 60.0))};
  }

  std::vector<LightDetection> AllLights(const Pose3& T_C_D) {
    std::vector<LightDetection> out;
    for (const DockLight& light : dock_.lights) out.push_back(Detection(Project(T_C_D, light.id)));
    return out;
  }

  // The ids of AllLights' detections, in their order.
  std::vector<int> AllLightIds() const {
    std::vector<int> ids;
    for (const DockLight& light : dock_.lights) ids.push_back(light.id);
    return ids;
  }

  // What PnP would give: the truth perturbed by its covariance (1 mrad, 1 cm).
  Pose3 Measured(const Pose3& truth) {
    const Eigen::Vector3d dtheta(1e-3 * noise_(rng_), 1e-3 * noise_(rng_), 1e-3 * noise_(rng_));
    const Eigen::Vector3d dp(1e-2 * noise_(rng_), 1e-2 * noise_(rng_), 1e-2 * noise_(rng_));
    return Pose3(ExpQuaternion(dtheta) * truth.q, truth.p + dp);
  }

  static Matrix6 PnpCovariance() {
    Matrix6 P = Matrix6::Zero();
    P.diagonal() << 1e-6, 1e-6, 1e-6, 1e-4, 1e-4, 1e-4;
    return P;
  }

  bool StartFromPoses(FewLightTracker* tracker, int first, int last) {
    std::vector<Pose3> poses;
    std::vector<Matrix6> covariances;
    for (int k = first; k <= last; ++k) {
      poses.push_back(Measured(Truth(k)));
      covariances.push_back(PnpCovariance());
    }
    return tracker->Start(poses, covariances);
  }

  PinholeRadtanCamera camera_;
  DockModel dock_;
  Pose3 start_;
  std::mt19937_64 rng_{7};
  std::normal_distribution<double> noise_{0.0, 0.3};
};

TEST_F(FewLightTrackerTest, FollowsTwoLightsForTwentyFramesAndRejectsASpeckFarFromThem) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&tracker, 0, 5));
  for (int k = 6; k <= 25; ++k) {
    const std::optional<FewLightStep> step = tracker.Step(TwoLightsAndASpeck(Truth(k)));
    ASSERT_TRUE(step) << "frame " << k << ": " << tracker.end_reason();
    EXPECT_EQ(step->light_ids, (std::vector<int>{0, 1, -1})) << "frame " << k;
    EXPECT_EQ(step->unexplained, (std::vector<bool>{false, false, true})) << "frame " << k;
    EXPECT_EQ(step->labelled, 2);
    // The pose follows the truth along what two lights and the rate tell.
    EXPECT_LT((step->T_C_D.p - Truth(k).p).norm(), 0.1) << "frame " << k;
  }
}

// A light too close to show its colour: the detector rejects it (a doubtful candidate), and the
// walk takes it where it predicts a light and no detection lies, never where a detection does.
TEST_F(FewLightTrackerTest, TakesADoubtfulCandidateOnlyWhereALightIsPredictedAndNothingElseIs) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&tracker, 0, 5));
  for (int k = 6; k <= 20; ++k) {
    const Pose3 T = Truth(k);
    // Light 0 detected; light 1 only as a doubtful candidate; a doubtful speck far from both.
    const std::vector<LightDetection> detections = {Detection(Project(T, 0))};
    const std::vector<LightDetection> doubtful = {
        Detection(Project(T, 1)), Detection(Project(T, 0) + Eigen::Vector2d(90.0, 60.0))};
    const std::optional<FewLightStep> step = tracker.Step(detections, doubtful);
    ASSERT_TRUE(step) << "frame " << k << ": " << tracker.end_reason();
    EXPECT_EQ(step->light_ids, (std::vector<int>{0})) << "frame " << k;
    EXPECT_EQ(step->doubtful_light_ids, (std::vector<int>{1, -1})) << "frame " << k;
    EXPECT_EQ(step->labelled, 1);
    EXPECT_EQ(std::count_if(step->doubtful_light_ids.begin(), step->doubtful_light_ids.end(),
                            [](int id) { return id >= 0; }),
              1);
    // Doubtful candidates are never judged: they are rejected already.
    EXPECT_EQ(step->unexplained, (std::vector<bool>{false}));
    EXPECT_LT((step->T_C_D.p - Truth(k).p).norm(), 0.1) << "frame " << k;
  }
  // Where a detection lies in light 1's gate, a doubtful candidate beside it is not taken.
  const Pose3 T = Truth(21);
  const std::optional<FewLightStep> step =
      tracker.Step({Detection(Project(T, 0)), Detection(Project(T, 1))},
                   {Detection(Project(T, 1) + Eigen::Vector2d(2.0, 0.0))});
  ASSERT_TRUE(step) << tracker.end_reason();
  EXPECT_EQ(step->light_ids, (std::vector<int>{0, 1}));
  EXPECT_EQ(step->doubtful_light_ids, (std::vector<int>{-1}));
}

// A prediction too uncertain in pixels still guides while it is small against the light's
// spacing in the image (a light within a metre moves by many pixels per frame).
TEST_F(FewLightTrackerTest, APredictionGuidesWhileSmallAgainstTheLightsSpacing) {
  FewLightTrackerOptions options;
  options.max_sigma_px = 0.2;  // below every prediction's sigma here
  options.guide_spacing_fraction = 0.0;
  FewLightTracker strict(camera_, dock_, 0.1, options);
  ASSERT_TRUE(StartFromPoses(&strict, 0, 5));
  EXPECT_FALSE(strict.Step(TwoLightsAndASpeck(Truth(6))));
  EXPECT_EQ(strict.end_reason(), "the prediction is too uncertain to guide");
  options.guide_spacing_fraction = 0.2;
  FewLightTracker relative(camera_, dock_, 0.1, options);
  ASSERT_TRUE(StartFromPoses(&relative, 0, 5));
  const std::optional<FewLightStep> step = relative.Step(TwoLightsAndASpeck(Truth(6)));
  ASSERT_TRUE(step) << relative.end_reason();
  EXPECT_EQ(step->light_ids, (std::vector<int>{0, 1, -1}));
}

// The downward camera lands over a light: it descends 2 cm a frame, then stops 0.46 m above it,
// and sees that light alone. One light does not observe the range; the walk's rate decays
// (acceleration_time_s) instead of carrying the descent on until the light is "behind" the lens.
TEST_F(FewLightTrackerTest, FollowsTheOneLightUnderALandedCamera) {
  const Eigen::Vector3d light_D = dock_.lights[0].p_D;
  const auto above = [&](int k) {  // looking down (camera z = dock z, down), axes aligned
    const double height = 0.7 - 0.02 * std::min(k, 12);
    return Pose3(Eigen::Quaterniond::Identity(), -(light_D - Eigen::Vector3d(0.0, 0.0, height)));
  };
  FewLightTracker tracker(camera_, dock_, 0.1);
  std::vector<Pose3> poses;
  std::vector<Matrix6> covariances;
  for (int k = 0; k <= 5; ++k) {
    poses.push_back(Measured(above(k)));
    covariances.push_back(PnpCovariance());
  }
  ASSERT_TRUE(tracker.Start(poses, covariances));
  for (int k = 6; k <= 60; ++k) {
    const Eigen::Vector2d uv = *camera_.Project(above(k) * light_D);
    const std::optional<FewLightStep> step = tracker.Step({Detection(uv)});
    ASSERT_TRUE(step) << "frame " << k << ": " << tracker.end_reason();
    EXPECT_EQ(step->light_ids, (std::vector<int>{0})) << "frame " << k;
  }
}

// Two doubtful candidates in one light's gate that are not one blob: neither is taken.
TEST_F(FewLightTrackerTest, NeverGuessesBetweenTwoDoubtfulCandidates) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&tracker, 0, 5));
  const Pose3 T = Truth(6);
  std::vector<LightDetection> doubtful = {Detection(Project(T, 1)),
                                          Detection(Project(T, 1) + Eigen::Vector2d(2.5, 0.0))};
  for (LightDetection& d : doubtful) d.radius_px = 1.0;  // two small blobs 2.5 px apart
  const std::optional<FewLightStep> step = tracker.Step({Detection(Project(T, 0))}, doubtful);
  ASSERT_TRUE(step) << tracker.end_reason();
  EXPECT_EQ(step->doubtful_light_ids, (std::vector<int>{-1, -1}));
  // The same blob at a larger scale (within its radius) is one candidate: the nearer is taken.
  const Pose3 T7 = Truth(7);
  doubtful = {Detection(Project(T7, 1) + Eigen::Vector2d(2.0, 0.0)), Detection(Project(T7, 1))};
  doubtful[0].radius_px = 20.0;
  const std::optional<FewLightStep> next = tracker.Step({Detection(Project(T7, 0))}, doubtful);
  ASSERT_TRUE(next) << tracker.end_reason();
  EXPECT_EQ(next->doubtful_light_ids, (std::vector<int>{-1, 1}));
}

TEST_F(FewLightTrackerTest, NeverGuessesBetweenTwoDetectionsInOneLightsGate) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&tracker, 0, 5));
  const Pose3 T = Truth(6);
  std::vector<LightDetection> detections = {Detection(Project(T, 0)), Detection(Project(T, 1)),
                                            Detection(Project(T, 0) + Eigen::Vector2d(1.0, 0.5))};
  const std::optional<FewLightStep> step = tracker.Step(detections);
  ASSERT_TRUE(step) << tracker.end_reason();
  EXPECT_EQ(step->light_ids, (std::vector<int>{-1, 1, -1}));
  // Both stay: each may be light 0.
  EXPECT_EQ(step->unexplained, (std::vector<bool>{false, false, false}));
}

// A glint 12 px beside a light that another detection is labelled as is a second detection of
// that light, no light of the dock; with that light unlabelled it might be the light, and stays.
TEST_F(FewLightTrackerTest, AGlintBesideALabelledLightIsNoLightOfTheDock) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&tracker, 0, 5));
  const Pose3 T = Truth(6);
  const Eigen::Vector2d stem = (Project(T, 1) - Project(T, 0)).normalized();
  const Eigen::Vector2d across(-stem.y(), stem.x());
  const LightDetection glint = Detection(Project(T, 0) + 12.0 * across);
  const std::optional<FewLightStep> step =
      tracker.Step({Detection(Project(T, 0)), Detection(Project(T, 1)), glint});
  ASSERT_TRUE(step) << tracker.end_reason();
  EXPECT_EQ(step->light_ids, (std::vector<int>{0, 1, -1}));
  EXPECT_EQ(step->unexplained, (std::vector<bool>{false, false, true}));

  FewLightTracker other(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&other, 0, 5));
  const std::optional<FewLightStep> without_light_0 =
      other.Step({Detection(Project(T, 1)), glint});
  ASSERT_TRUE(without_light_0) << other.end_reason();
  EXPECT_EQ(without_light_0->light_ids, (std::vector<int>{1, -1}));
  EXPECT_EQ(without_light_0->unexplained, (std::vector<bool>{false, false}));
}

TEST_F(FewLightTrackerTest, AJerkTheRateCannotFollowIsNotJudgedAndEndsTheWalk) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  ASSERT_TRUE(StartFromPoses(&tracker, 0, 5));
  for (int k = 6; k < 9; ++k) ASSERT_TRUE(tracker.Step(TwoLightsAndASpeck(Truth(k))));
  // A 15 degree turn between two frames (the rate model allows about 0.1 rad in a second): every
  // light moves by a hundred pixels.
  const int jerk = 9;
  int judged = 0;
  for (int k = jerk; k < jerk + 5; ++k) {
    const std::optional<FewLightStep> step =
        tracker.Step(TwoLightsAndASpeck(Truth(k, jerk, 15.0 * M_PI / 180.0)));
    if (!step) break;
    for (size_t j = 0; j < step->light_ids.size(); ++j) {
      judged += step->light_ids[j] >= 0 || step->unexplained[j];
    }
  }
  EXPECT_EQ(judged, 0);
  EXPECT_FALSE(tracker.walking());
  EXPECT_NE(tracker.end_reason().find("lost"), std::string::npos) << tracker.end_reason();
}

TEST_F(FewLightTrackerTest, NeedsThreeConsecutivePosesToStart) {
  FewLightTracker tracker(camera_, dock_, 0.1);
  EXPECT_FALSE(StartFromPoses(&tracker, 0, 1));
  EXPECT_FALSE(tracker.Step(TwoLightsAndASpeck(Truth(2))));
  EXPECT_THROW(FewLightTracker(camera_, dock_, 0.0), std::invalid_argument);
}

// Frames 0-5 and 11, 13-17 show two lights and a speck; 6-10 all lights with a pose; 12 a lone
// pose of its own (labels that the walk must leave alone).
TEST_F(FewLightTrackerTest, TheBridgeWalksBothWaysFromAPosedRunAndThroughALonePose) {
  std::vector<BridgedFrame> frames(18);
  for (int k = 0; k < 18; ++k) {
    const bool posed = (k >= 6 && k <= 10) || k == 12;
    frames[k].detections = posed ? AllLights(Truth(k)) : TwoLightsAndASpeck(Truth(k));
    if (posed) {
      frames[k].T_C_D = Measured(Truth(k));
      frames[k].covariance_local = PnpCovariance();
      frames[k].tracked = k >= 7 && k <= 10;  // 6 and the lone 12 from scratch
      frames[k].own_light_ids = AllLightIds();
    }
  }
  TwoWayLightBridgeOptions options;
  std::vector<BridgedFrame> both = frames;
  EXPECT_EQ(BridgeFramesWithoutPose(camera_, dock_, 0.1, options, &both), 12);
  for (int k = 0; k < 18; ++k) {
    if (both[k].T_C_D) {
      EXPECT_FALSE(both[k].bridged) << "frame " << k;
      continue;
    }
    ASSERT_TRUE(both[k].bridged) << "frame " << k;
    EXPECT_EQ(both[k].anchor_frame, k < 6 ? 6 : 10) << "frame " << k;
    EXPECT_EQ(both[k].light_ids, (std::vector<int>{0, 1, -1})) << "frame " << k;
    EXPECT_EQ(both[k].unexplained, (std::vector<bool>{false, false, true})) << "frame " << k;
  }
  options.backward = false;
  std::vector<BridgedFrame> forward = frames;
  EXPECT_EQ(BridgeFramesWithoutPose(camera_, dock_, 0.1, options, &forward), 6);
  for (int k = 0; k < 6; ++k) EXPECT_FALSE(forward[k].bridged) << "frame " << k;
}

// Frames after the posed run where light 1 is only a doubtful candidate (rejected for its
// colour): the bridge puts light 1 on it; a doubtful speck stays unlabelled.
TEST_F(FewLightTrackerTest, TheBridgePutsALightOnADoubtfulCandidate) {
  std::vector<BridgedFrame> frames(14);
  for (int k = 0; k < 14; ++k) {
    const Pose3 T = Truth(k);
    if (k < 6) {
      frames[k].detections = AllLights(T);
      frames[k].T_C_D = Measured(T);
      frames[k].covariance_local = PnpCovariance();
      frames[k].tracked = k > 0;
      frames[k].own_light_ids = AllLightIds();
      continue;
    }
    frames[k].detections = {Detection(Project(T, 0))};
    frames[k].doubtful = {Detection(Project(T, 0) + Eigen::Vector2d(90.0, 60.0)),
                          Detection(Project(T, 1))};
  }
  EXPECT_EQ(BridgeFramesWithoutPose(camera_, dock_, 0.1, {}, &frames), 8);
  for (int k = 6; k < 14; ++k) {
    ASSERT_TRUE(frames[k].bridged) << "frame " << k;
    EXPECT_EQ(frames[k].light_ids, (std::vector<int>{0})) << "frame " << k;
    EXPECT_EQ(frames[k].doubtful_light_ids, (std::vector<int>{-1, 1})) << "frame " << k;
  }
}

// A chain of 20 true poses (frames 10-29) after a chain of 6 tracked poses (4-9) whose labels
// take one light and three specks for the dock, 1 m off, while the five other lights stay
// unexplained beside them (as tracking carried one in the renders): walking back from the longer chain labels more of frame 9 than its own pose did,
// so the short chain is refuted, its poses withdrawn, and its frames bridged with the true labels.
TEST_F(FewLightTrackerTest, ALongerChainRefutesAWrongTrackedChainBesideIt) {
  std::vector<BridgedFrame> frames(30);
  for (int k = 4; k < 30; ++k) {
    BridgedFrame& f = frames[k];
    if (k >= 10) {
      f.detections = AllLights(Truth(k));
      f.own_light_ids = AllLightIds();
      f.T_C_D = Measured(Truth(k));
    } else {
      // Every light and three specks; the wrong pose "identifies" light 4 and the specks.
      f.detections = AllLights(Truth(k));
      for (const Eigen::Vector2d& corner : {Eigen::Vector2d(40.0, 40.0),
                                           Eigen::Vector2d(600.0, 40.0),
                                           Eigen::Vector2d(40.0, 470.0)}) {
        f.detections.push_back(Detection(corner));
      }
      f.own_light_ids = {-1, -1, -1, -1, 4, -1, 0, 1, 2};
      f.T_C_D = Pose3(Truth(k).q, Truth(k).p + Eigen::Vector3d(1.0, 0.0, 0.0));
    }
    f.covariance_local = PnpCovariance();
    f.tracked = k != 4 && k != 10;
  }
  TwoWayLightBridgeOptions options;
  std::vector<BridgedFrame> refuted = frames;
  BridgeFramesWithoutPose(camera_, dock_, 0.1, options, &refuted);
  for (int k = 4; k < 10; ++k) {
    EXPECT_TRUE(refuted[k].refuted) << "frame " << k;
    EXPECT_EQ(refuted[k].refuted_by, 10) << "frame " << k;
    ASSERT_TRUE(refuted[k].bridged) << "frame " << k;
    EXPECT_EQ(refuted[k].light_ids, (std::vector<int>{0, 1, 2, 3, 4, 5, -1, -1, -1}))
        << "frame " << k;
  }
  for (int k = 10; k < 30; ++k) EXPECT_FALSE(refuted[k].refuted) << "frame " << k;

  // Where the walk labels fewer more than the margin asks (6 against 4 + 3), the wrong chain
  // stands and nothing is bridged across it.
  options.refute_margin = 3;
  std::vector<BridgedFrame> standing = frames;
  BridgeFramesWithoutPose(camera_, dock_, 0.1, options, &standing);
  for (int k = 4; k < 10; ++k) {
    EXPECT_FALSE(standing[k].refuted) << "frame " << k;
    EXPECT_FALSE(standing[k].bridged) << "frame " << k;
  }
}

// A lone pose from scratch among frames with too few lights for one (frame 13), which takes two
// specks for lights 3 and 4, 0.5 m off: the walk from the posed run before it judges both specks
// no light of the dock, so the lone pose is refuted, and its frame bridged. The same frame with
// its true pose stands, and so does the wrong one with lone_refute_contradicted 0.
TEST_F(FewLightTrackerTest, ALonePoseThatTakesWhatTheWalkJudgesNoLightForLightsIsRefuted) {
  std::vector<BridgedFrame> frames(18);
  for (int k = 0; k < 18; ++k) {
    BridgedFrame& f = frames[k];
    if (k < 10) {
      f.detections = AllLights(Truth(k));
      f.own_light_ids = AllLightIds();
      f.T_C_D = Measured(Truth(k));
      f.covariance_local = PnpCovariance();
      f.tracked = k > 0;
      continue;
    }
    f.detections = TwoLightsAndASpeck(Truth(k));
    if (k == 13) {
      f.detections.push_back(Detection(Project(Truth(k), 0) + Eigen::Vector2d(90.0, -60.0)));
      f.own_light_ids = {0, 1, 3, 4};
      f.T_C_D = Pose3(Truth(k).q, Truth(k).p + Eigen::Vector3d(0.5, 0.0, 0.0));
      f.covariance_local = PnpCovariance();
    }
  }
  TwoWayLightBridgeOptions options;
  std::vector<BridgedFrame> refuted = frames;
  BridgeFramesWithoutPose(camera_, dock_, 0.1, options, &refuted);
  EXPECT_TRUE(refuted[13].refuted);
  EXPECT_EQ(refuted[13].refuted_by, 9);
  EXPECT_EQ(refuted[13].contradicted, 2);
  ASSERT_TRUE(refuted[13].bridged);
  EXPECT_EQ(refuted[13].light_ids, (std::vector<int>{0, 1, -1, -1}));
  for (int k = 0; k < 18; ++k) {
    if (k != 13) {
      EXPECT_FALSE(refuted[k].refuted) << "frame " << k;
    }
  }

  options.lone_refute_contradicted = 0;
  std::vector<BridgedFrame> standing = frames;
  BridgeFramesWithoutPose(camera_, dock_, 0.1, options, &standing);
  EXPECT_FALSE(standing[13].refuted);

  std::vector<BridgedFrame> true_lone = frames;
  true_lone[13].detections = AllLights(Truth(13));
  true_lone[13].own_light_ids = AllLightIds();
  true_lone[13].T_C_D = Measured(Truth(13));
  BridgeFramesWithoutPose(camera_, dock_, 0.1, TwoWayLightBridgeOptions(), &true_lone);
  EXPECT_FALSE(true_lone[13].refuted);
}

}  // namespace
}  // namespace auvdock
