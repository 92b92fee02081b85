// Hand labels (LoadLightLabels) and the detector measure against them (EvaluateDetections):
// known answers on small hand-made cases, and the errors of a malformed labels file.
#include "auvdock/eval/detection_evaluation.h"

#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

TEST(LoadLightLabels, ReadsQuotedFieldsStatusesAndEmptyFrames) {
  test::TempDir dir;
  test::WriteTextFile(dir / "labels.csv",
                      "frame_file,frame_index,u,v,status,quality\n"
                      "a.jpg,0,,,none,no LED visible\n"
                      "b.jpg,20,10.5,20.25,ok,good\n"
                      "b.jpg,20,30,40,border,smeared\n"
                      "b.jpg,20,700,5,edge,\"glow only, centre not visible\"\n"
                      "c.jpg,40,1,2,ok,uncertain\n");
  const LightLabels labels = LoadLightLabels(dir / "labels.csv");
  ASSERT_EQ(labels.size(), 3u);
  EXPECT_TRUE(labels.at("a.jpg").empty());
  const auto& b = labels.at("b.jpg");
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[0].uv, Eigen::Vector2d(10.5, 20.25));
  EXPECT_EQ(b[0].status, LabelStatus::kOk);
  EXPECT_TRUE(b[0].good);
  EXPECT_EQ(b[1].status, LabelStatus::kBorder);
  EXPECT_FALSE(b[1].good);
  EXPECT_EQ(b[2].status, LabelStatus::kEdge);
  EXPECT_FALSE(labels.at("c.jpg")[0].good);
}

TEST(EvaluateDetections, LabelsBeyondTheMaximumRangeAreNotRequired) {
  test::TempDir dir;
  test::WriteTextFile(dir / "l.csv",
                      "frame_file,light_id,u,v,status,range_m\n"
                      "a.png,0,10,10,ok,3.5\n"
                      "a.png,1,50,10,ok,9.0\n"
                      "a.png,2,90,10,ok,\n");
  const LightLabels labels = LoadLightLabels(dir / "l.csv");
  EXPECT_DOUBLE_EQ(labels.at("a.png")[0].range_m, 3.5);
  EXPECT_LT(labels.at("a.png")[2].range_m, 0.0);  // unknown
  std::map<std::string, FrameDetections> frames;
  frames["a.png"].uv = {Eigen::Vector2d(10.5, 10.0), Eigen::Vector2d(50.0, 10.5)};
  DetectionEvaluationOptions options;
  const DetectionEvaluation all = EvaluateDetections(labels, frames, options);
  EXPECT_EQ(all.ok_labels, 3);
  EXPECT_EQ(all.hits, 2);
  options.max_range_m = 8.0;
  const DetectionEvaluation near = EvaluateDetections(labels, frames, options);
  EXPECT_EQ(near.ok_labels, 2);  // the 9 m light is not required; the one of unknown range is
  EXPECT_EQ(near.hits, 1);
  EXPECT_DOUBLE_EQ(near.precision, 1.0);  // the far light's detection is still a hit
  test::WriteTextFile(dir / "bad.csv", "frame_file,u,v,range_m\na.png,1,2,-3\n");
  EXPECT_THROW(LoadLightLabels(dir / "bad.csv"), InputError);
}

TEST(LoadLightLabels, MinimalColumnsDefaultToOkAndGood) {
  test::TempDir dir;
  test::WriteTextFile(dir / "l.csv", "u,v,frame_file\n3,4,x.png\n");
  const LightLabels labels = LoadLightLabels(dir / "l.csv");
  EXPECT_EQ(labels.at("x.png")[0].status, LabelStatus::kOk);
  EXPECT_TRUE(labels.at("x.png")[0].good);
}

void ExpectError(const std::string& text, const std::string& needle) {
  test::TempDir dir;
  test::WriteTextFile(dir / "bad.csv", text);
  try {
    LoadLightLabels(dir / "bad.csv");
    FAIL() << "no error for " << text;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.csv"), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

TEST(LoadLightLabels, MalformedFilesNameTheLineAndColumn) {
  ExpectError("image,u,v\na,1,2\n", "frame_file, u and v");
  ExpectError("frame_file,u,v\na,1,x\n", "line 2: column 'v'");
  ExpectError("frame_file,u,v\na,nan,1\n", "column 'u'");
  ExpectError("frame_file,u,v,status\na,1,2,maybe\n", "column 'status'");
  ExpectError("frame_file,u,v\na,1\n", "line 2");
  ExpectError("frame_file,u,v\n\"a,1,2\n", "unterminated quote");
  ExpectError("frame_file,u,v\n", "no labelled frame");
}

TEST(EvaluateDetections, KnownAnswer) {
  LightLabels labels;
  labels["f1"] = {{Eigen::Vector2d(100, 100), LabelStatus::kOk, true},
                  {Eigen::Vector2d(200, 100), LabelStatus::kOk, true},
                  {Eigen::Vector2d(300, 100), LabelStatus::kOk, false},
                  {Eigen::Vector2d(400, 100), LabelStatus::kBorder, true},
                  {Eigen::Vector2d(719, 5), LabelStatus::kEdge, true}};
  labels["f2"] = {};
  labels["f3"] = {{Eigen::Vector2d(50, 50), LabelStatus::kOk, true}};  // never processed
  std::map<std::string, FrameDetections> frames;
  frames["f1"].uv = {Eigen::Vector2d(103, 104),   // hit on 100,100: 5 px
                     Eigen::Vector2d(101, 99),    // nearer: takes 100,100 (1.41 px) first
                     Eigen::Vector2d(300, 109),   // hit on a non-good label: not in the RMS
                     Eigen::Vector2d(401, 100),   // hit on a border label
                     Eigen::Vector2d(710, 10),    // near the edge label: not counted
                     Eigen::Vector2d(600, 300)};  // false
  frames["f1"].has_pose = true;
  frames["f2"].uv = {Eigen::Vector2d(1, 1)};      // false
  DetectionEvaluationOptions options;
  options.min_lights_for_pose = 3;
  const DetectionEvaluation e = EvaluateDetections(labels, frames, options);
  EXPECT_EQ(e.frames, 2);
  EXPECT_EQ(e.missing_frames, 1);
  EXPECT_EQ(e.ok_labels, 3);
  EXPECT_EQ(e.hits, 2);  // 100,100 and 300,100; 200,100 is missed (103,104 is 97 px away)
  EXPECT_DOUBLE_EQ(e.recall, 2.0 / 3.0);
  EXPECT_EQ(e.detections, 6);  // 3 true (incl. the border hit), 103,104 + 600,300 + 1,1 false
  EXPECT_EQ(e.true_detections, 3);
  EXPECT_DOUBLE_EQ(e.precision, 0.5);
  EXPECT_EQ(e.centroid_samples, 1);
  EXPECT_NEAR(e.centroid_rms_px, std::sqrt(2.0), 1e-12);
  EXPECT_EQ(e.pose_frames_eligible, 1);
  EXPECT_EQ(e.pose_frames, 1);
  EXPECT_EQ(e.missed.size(), 1u);
  EXPECT_EQ(e.false_detections.size(), 3u);
}

}  // namespace
}  // namespace auvdock
