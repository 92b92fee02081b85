// ReasonClass groups alike "why not" reasons under a sentence that still reads.
#include "apps/reason_class.h"

#include <gtest/gtest.h>

namespace auvdock::cli {
namespace {

TEST(ReasonClassTest, FiguresBecomeNAndDetailsAreDropped) {
  EXPECT_EQ(ReasonClass("only 2 detections (need 4)"), "only N detections");
  EXPECT_EQ(ReasonClass("only 3 detections (need 4) (24 candidates rejected; most often: extended)"),
            "only N detections");
  EXPECT_EQ(ReasonClass("ambiguous: two labellings explain 4 detections: {d0=L1 d2=L2} (rms 1.28 px)"),
            "ambiguous: two labellings explain N detections");
  EXPECT_EQ(ReasonClass("failed: at the verified pose: the 4 matches are not consistent"),
            "failed: at the verified pose: the N matches are not consistent");
  EXPECT_EQ(ReasonClass("fit rms 1.5e-3 px above 2.25 px."), "fit rms N px above N px");
  EXPECT_EQ(ReasonClass("pose known only up to the dock's 4-fold symmetry"),
            "pose known only up to the dock's N-fold symmetry");
}

TEST(ReasonClassTest, AlikeReasonsShareAClassAndOthersDoNot) {
  EXPECT_EQ(ReasonClass("only 1 detections (need 4)"), ReasonClass("only 0 detections (need 4)"));
  EXPECT_NE(ReasonClass("only 1 detections (need 4)"),
            ReasonClass("no pose explains more than 3 detections (need 4)"));
}

TEST(ReasonClassTest, AReasonWithoutDetailIsItselfAndAnEmptyClassFallsBackToTheText) {
  EXPECT_EQ(ReasonClass("no identified light"), "no identified light");
  EXPECT_EQ(ReasonClass("(nothing)"), "(nothing)");
}

}  // namespace
}  // namespace auvdock::cli
