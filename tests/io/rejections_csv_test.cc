#include "auvdock/io/rejections_csv.h"

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

void WriteLines(const std::string& path, const std::vector<std::string>& rows) {
  std::ofstream out(path);
  out << RejectionsCsvHeader() << "\n";
  for (const std::string& row : rows) out << row << "\n";
}

TEST(RejectionsCsvTest, WriteThenReadKeepsEveryRejection) {
  const test::TempDir dir;
  const std::vector<Rejection> rejections = {
      {100, "dvl0", 2190.5, "beyond the chi-square gate"},
      {100, "cam0", 23.25, "light 1: beyond the stereo gate"},
      {50, "depth0", kNoStatistic, "out of order, or repeated"}};
  std::vector<std::string> rows;
  for (const Rejection& r : rejections) rows.push_back(RejectionsCsvRow(r));
  WriteLines(dir / "rejections.csv", rows);
  const std::vector<Rejection> read = ReadRejectionsCsv(dir / "rejections.csv");
  ASSERT_EQ(read.size(), 3u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(read[k].t_ns, rejections[k].t_ns);
    EXPECT_EQ(read[k].sensor, rejections[k].sensor);
    EXPECT_DOUBLE_EQ(read[k].statistic, rejections[k].statistic);
    EXPECT_EQ(read[k].reason, rejections[k].reason);
  }
  EXPECT_TRUE(std::isnan(read[2].statistic));
  EXPECT_EQ(read[2].reason, "out of order; or repeated");  // one field, no comma
}

TEST(RejectionsCsvTest, AMalformedRowNamesTheFileAndLine) {
  const test::TempDir dir;
  const std::string path = dir / "rejections.csv";
  WriteLines(path, {"100,dvl0,12.5,beyond the chi-square gate", "200,dvl0,abc,beyond"});
  try {
    ReadRejectionsCsv(path);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("line 3"));
  }
  WriteLines(path, {"100,,12.5,beyond the chi-square gate"});
  EXPECT_THROW(ReadRejectionsCsv(path), InputError);
}

}  // namespace
}  // namespace auvdock
