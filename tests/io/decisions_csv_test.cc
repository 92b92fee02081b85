#include "auvdock/io/decisions_csv.h"

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
  out << DecisionsCsvHeader() << "\n";
  for (const std::string& row : rows) out << row << "\n";
}

std::string ReadError(const std::string& path) {
  try {
    ReadDecisionsCsv(path);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(DecisionsCsvTest, WriteThenReadKeepsEveryDecision) {
  const test::TempDir dir;
  const std::vector<StampedDecision> decisions = {
      {100, false, "no estimate: waiting for a per-frame pose"},
      {200, true, "3-sigma lateral 0.076 m and yaw 0.0056 rad within limits"},
      {300, false, "a reason, with a comma"}};
  std::vector<std::string> rows;
  for (const StampedDecision& d : decisions) rows.push_back(DecisionsCsvRow(d));
  WriteLines(dir / "decisions.csv", rows);
  const std::vector<StampedDecision> read = ReadDecisionsCsv(dir / "decisions.csv");
  ASSERT_EQ(read.size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(read[k].t_ns, decisions[k].t_ns);
    EXPECT_EQ(read[k].go, decisions[k].go);
  }
  EXPECT_EQ(read[1].reason, decisions[1].reason);
  EXPECT_EQ(read[2].reason, "a reason; with a comma");
}

TEST(DecisionsCsvTest, BadRowsNameTheFileAndLine) {
  const test::TempDir dir;
  const std::string path = dir / "decisions.csv";
  WriteLines(path, {"100,GO,fine", "200,MAYBE,unsure"});
  EXPECT_THAT(ReadError(path), HasSubstr("decisions.csv: line 3: column 'decision'"));
  WriteLines(path, {"100,GO,fine", "100,NO-GO,repeated"});
  EXPECT_THAT(ReadError(path), HasSubstr("line 3: timestamp 100 is not after"));
  WriteLines(path, {"100,GO"});
  EXPECT_THAT(ReadError(path), HasSubstr("line 2"));
}

}  // namespace
}  // namespace auvdock
