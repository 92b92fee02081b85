// Identities given with the detections (vision/given_identity_check.h): right claims are kept
// with the true pose, a wrong claim is left out, claims that cannot be right fail (so the
// caller identifies the image itself).
#include "auvdock/vision/given_identity_check.h"

#include <random>

#include <gtest/gtest.h>

#include "tests/testing/dock_views.h"

namespace auvdock {
namespace {

class GivenIdentityCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dock_ = test::LoadDock("t_shape.yaml");
    camera_ = test::DefaultMonoCamera();
  }
  test::View View(std::mt19937_64& rng, int num_spurious) {
    const Pose3 T_C_D = test::RandomView(dock_, camera_, 0.3, rng);
    return test::MakeView(dock_, camera_, T_C_D, test::AllLightIds(dock_), num_spurious, 0.3, rng);
  }
  DockModel dock_;
  PinholeRadtanCamera camera_;
};

TEST_F(GivenIdentityCheckTest, RightClaimsAreKeptWithTheTruePose) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const test::View view = View(rng, 2);
    const GivenIdentityCheck check =
        CheckGivenIdentities(view.detections, view.truth, dock_, camera_, {}, std::nullopt);
    ASSERT_EQ(check.match.status, MatchStatus::kOk) << check.match.reason;
    EXPECT_EQ(check.dropped, 0);
    EXPECT_EQ(check.match.matches.size(), dock_.lights.size());
    for (const LightMatch& m : check.match.matches) EXPECT_EQ(view.truth[m.detection], m.light_id);
    ASSERT_TRUE(check.T_C_D);
    EXPECT_LT((check.T_C_D->p - view.T_C_D.p).norm(), 0.05 * view.T_C_D.p.norm());
  }
}

TEST_F(GivenIdentityCheckTest, AWrongClaimIsLeftOut) {
  std::mt19937_64 rng(4);
  int left_out_right = 0;
  const int trials = 20;
  for (int trial = 0; trial < trials; ++trial) {
    const test::View view = View(rng, 0);
    std::vector<int> claims = view.truth;
    // One light claims another's identity that no other detection claims: a swap would keep
    // both lights' claims wrong; here the claimed light's own detection is dropped first.
    const size_t wrong = static_cast<size_t>(trial) % claims.size();
    const size_t victim = (wrong + 2) % claims.size();
    claims[wrong] = view.truth[victim];
    claims[victim] = -1;
    const GivenIdentityCheck check =
        CheckGivenIdentities(view.detections, claims, dock_, camera_, {}, std::nullopt);
    ASSERT_EQ(check.match.status, MatchStatus::kOk) << check.match.reason;
    bool kept_wrong = false;
    for (const LightMatch& m : check.match.matches) {
      if (view.truth[m.detection] != m.light_id) kept_wrong = true;
    }
    if (!kept_wrong && check.dropped == 1) ++left_out_right;
  }
  EXPECT_EQ(left_out_right, trials);
}

TEST_F(GivenIdentityCheckTest, ALightClaimedTwiceKeepsTheHigherScore) {
  std::mt19937_64 rng(5);
  test::View view = View(rng, 1);
  std::vector<int> claims = view.truth;
  size_t spurious = 0;
  while (view.truth[spurious] != -1) ++spurious;
  claims[spurious] = dock_.lights.front().id;  // score 0.5 against the light's 1
  const GivenIdentityCheck check =
      CheckGivenIdentities(view.detections, claims, dock_, camera_, {}, std::nullopt);
  ASSERT_EQ(check.match.status, MatchStatus::kOk) << check.match.reason;
  EXPECT_EQ(check.dropped, 1);
  for (const LightMatch& m : check.match.matches) EXPECT_EQ(view.truth[m.detection], m.light_id);
}

TEST_F(GivenIdentityCheckTest, ClaimsThatCannotBeRightFail) {
  std::mt19937_64 rng(6);
  const test::View view = View(rng, 0);
  // Too few.
  std::vector<int> few(view.truth.size(), -1);
  few[0] = view.truth[0];
  few[1] = view.truth[1];
  const GivenIdentityCheck too_few =
      CheckGivenIdentities(view.detections, few, dock_, camera_, {}, std::nullopt);
  EXPECT_EQ(too_few.match.status, MatchStatus::kFailed);
  EXPECT_NE(too_few.match.reason.find("too few claimed lights: 2, 4 needed"), std::string::npos)
      << too_few.match.reason;
  // Every identity shifted by one: no pose fits them.
  std::vector<int> shifted = view.truth;
  for (size_t i = 0; i < shifted.size(); ++i) shifted[i] = view.truth[(i + 1) % shifted.size()];
  const GivenIdentityCheck wrong =
      CheckGivenIdentities(view.detections, shifted, dock_, camera_, {}, std::nullopt);
  EXPECT_EQ(wrong.match.status, MatchStatus::kFailed);
  EXPECT_NE(wrong.match.reason.find("do not fit the dock"), std::string::npos);
  // An id that is not a light of the dock is no claim.
  std::vector<int> unknown(view.truth.size(), 77);
  EXPECT_EQ(CheckGivenIdentities(view.detections, unknown, dock_, camera_, {}, std::nullopt)
                .match.status,
            MatchStatus::kFailed);
}

}  // namespace
}  // namespace auvdock
