// The SBL range file: one row per transducer and ping, (timestamp, transducer) increasing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"
#include "auvdock/io/sensor_csv.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

std::string File(const std::vector<std::string>& rows) {
  std::string text = std::string(kSblCsvHeader) + "\n";
  for (const std::string& row : rows) text += row + "\n";
  return text;
}

TEST(SblCsvTest, RowsReadBackBitExact) {
  const std::vector<SblRange> ranges = {
      {1000, 0, 8.755412222554, 0.02}, {1000, 3, 9.1, 0.0182}, {2000, 1, 0.1 + 0.2, 0.05}};
  std::vector<std::string> rows;
  for (const SblRange& r : ranges) rows.push_back(SblCsvRow(r));
  test::TempDir dir;
  test::WriteTextFile(dir / "data.csv", File(rows));
  const std::vector<SblRange> read = ReadSblCsv(dir / "data.csv", 4);
  ASSERT_EQ(read.size(), ranges.size());
  for (size_t i = 0; i < ranges.size(); ++i) {
    EXPECT_EQ(read[i].t_ns, ranges[i].t_ns);
    EXPECT_EQ(read[i].transducer, ranges[i].transducer);
    EXPECT_EQ(read[i].range_m, ranges[i].range_m);
    EXPECT_EQ(read[i].sigma_m, ranges[i].sigma_m);
  }
}

void ExpectError(const std::vector<std::string>& rows, const std::string& what) {
  test::TempDir dir;
  test::WriteTextFile(dir / "data.csv", File(rows));
  try {
    ReadSblCsv(dir / "data.csv", 4);
    FAIL() << "expected InputError for: " << what;
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("data.csv: line"));
    EXPECT_THAT(e.what(), HasSubstr(what));
  }
}

TEST(SblCsvTest, BadRowsNameTheFileLineAndWhy) {
  ExpectError({"1000,4,5.0,0.02"}, "transducer index from 0 to 3");
  ExpectError({"1000,-1,5.0,0.02"}, "transducer index");
  ExpectError({"1000,0,-5.0,0.02"}, "cannot be negative");
  ExpectError({"1000,0,5.0,0"}, "must be positive");
  ExpectError({"1000,1,5.0,0.02", "1000,1,5.1,0.02"}, "timestamp, then transducer");
  ExpectError({"2000,0,5.0,0.02", "1000,1,5.1,0.02"}, "timestamp, then transducer");
  ExpectError({"1000,0,nan,0.02"}, "NaN/Inf");
}

TEST(SblCsvTest, LenientReadingSkipsNonFiniteAndOutOfOrderRows) {
  test::TempDir dir;
  test::WriteTextFile(dir / "data.csv", File({"1000,0,5.0,0.02", "1000,1,inf,0.02",
                                              "1000,0,5.2,0.02", "1000,2,5.1,0.02"}));
  std::vector<std::string> skipped;
  const std::vector<SblRange> read = ReadSblCsv(dir / "data.csv", 4, &skipped);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[1].transducer, 2);
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_THAT(skipped[0], HasSubstr("line 3: NaN/Inf"));
  EXPECT_THAT(skipped[1], HasSubstr("line 4: not after the previous row"));
}

}  // namespace
}  // namespace auvdock
