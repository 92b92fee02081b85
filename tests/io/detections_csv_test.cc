// detections.csv (io/detections_csv.h): what the writer writes the reader reads back, an image
// that saw nothing survives the round trip, and every malformed row names the file and line.
#include "auvdock/io/detections_csv.h"

#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

LightDetection Detection(double u, double v, double score) {
  LightDetection d;
  d.uv = Eigen::Vector2d(u, v);
  d.radius_px = 3.25;
  d.score = score;
  return d;
}

TEST(DetectionsCsvTest, WriteThenReadKeepsEveryImage) {
  const test::TempDir dir;
  const std::string path = dir / "detections.csv";
  {
    DetectionsCsvWriter writer(path);
    LightDetection with_covariance = Detection(100.5, 200.25, 0.75);
    with_covariance.covariance << 0.04, 0.01, 0.01, 0.09;
    writer.Append(2000, "cam1", {Detection(10, 20, 1.0)}, {});
    writer.Append(1000, "cam1", {with_covariance, Detection(30.125, 40, 0.5)}, {3, -1});
    writer.Append(1000, "cam0", {}, {});
    writer.Close();
  }
  const std::vector<ImageDetections> images = ReadDetectionsCsv(path);
  ASSERT_EQ(images.size(), 3u);
  // By camera, then time.
  EXPECT_EQ(images[0].camera, "cam0");
  EXPECT_EQ(images[0].t_ns, 1000);
  EXPECT_TRUE(images[0].detections.empty());
  EXPECT_EQ(images[1].camera, "cam1");
  EXPECT_EQ(images[1].t_ns, 1000);
  EXPECT_EQ(images[2].t_ns, 2000);
  ASSERT_EQ(images[1].detections.size(), 2u);
  EXPECT_EQ(images[1].light_ids, (std::vector<int>{3, -1}));
  EXPECT_EQ(images[2].light_ids, (std::vector<int>{-1}));  // a missing id is -1
  const LightDetection& d = images[1].detections[0];
  EXPECT_DOUBLE_EQ(d.uv.x(), 100.5);
  EXPECT_DOUBLE_EQ(d.uv.y(), 200.25);
  EXPECT_DOUBLE_EQ(d.radius_px, 3.25);
  EXPECT_DOUBLE_EQ(d.score, 0.75);
  EXPECT_DOUBLE_EQ(d.covariance(0, 0), 0.04);
  EXPECT_DOUBLE_EQ(d.covariance(0, 1), 0.01);
  EXPECT_DOUBLE_EQ(d.covariance(1, 0), 0.01);
  EXPECT_DOUBLE_EQ(d.covariance(1, 1), 0.09);
  EXPECT_TRUE(images[1].detections[1].covariance.isZero());
}

TEST(DetectionsCsvTest, TheCovarianceColumnsMayBeLeftOut) {
  const test::TempDir dir;
  const std::string path = dir / "detections.csv";
  test::WriteTextFile(path,
                      "#timestamp_ns,camera,light_id,u,v,radius,score\n"
                      "5,cam0,2,1.5,2.5,3,1\n"
                      "5,cam0,-1,7,8,2,0.4\n"
                      "9,cam0,-1,,,,\n");
  const std::vector<ImageDetections> images = ReadDetectionsCsv(path);
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0].light_ids, (std::vector<int>{2, -1}));
  EXPECT_EQ(images[0].line, 2);
  EXPECT_TRUE(images[1].detections.empty());
}

TEST(DetectionsCsvTest, AMalformedRowNamesTheFileAndLine) {
  const test::TempDir dir;
  const std::string path = dir / "detections.csv";
  const std::string header = "#timestamp_ns,camera,light_id,u,v,radius,score,cov_uu,cov_uv,cov_vv\n";
  const std::string good = "5,cam0,2,1.5,2.5,3,1,,,\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"5,cam0,2,abc,2.5,3,1,,,\n", "line 3"},
      {"5,,2,1.5,2.5,3,1,,,\n", "empty camera name"},
      {"5,cam0,-2,1.5,2.5,3,1,,,\n", "light id"},
      {"5,cam0,1,1.5,2.5,-3,1,,,\n", "must not be negative"},
      {"5,cam0,1,1.5,2.5,3,1.5,,,\n", "[0, 1]"},
      {"5,cam0,1,1.5,2.5,3,1,0.1,0.0\n", "all three"},
      {"5,cam0,1,1.5,2.5,3,1,0.1,0.5,0.1\n", "positive semi-definite"},
      {"5,cam0,-1,,,,,,,\n", "saw nothing"},
      {"6,cam0,3,,,,,,,\n", "light_id -1"},
  };
  for (const auto& [row, expected] : cases) {
    test::WriteTextFile(path, header + good + row);
    try {
      ReadDetectionsCsv(path);
      ADD_FAILURE() << "no InputError for " << row;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(path)) << row;
      EXPECT_THAT(e.what(), HasSubstr("line 3")) << row;
      EXPECT_THAT(e.what(), HasSubstr(expected)) << row;
    }
  }
  EXPECT_THROW(ReadDetectionsCsv(dir / "missing.csv"), InputError);
}

}  // namespace
}  // namespace auvdock
