#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"
#include "auvdock/io/sensor_csv.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

// Row 3 (file line 4) has NaN, row 5 (line 6) repeats a timestamp.
const char kImuWithBadRows[] =
    "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n"
    "1000,0,0,0,0,0,-9.81\n"
    "2000,0,0,0,0,0,-9.81\n"
    "3000,nan,0,0,0,0,-9.81\n"
    "4000,0,0,0,0,0,-9.81\n"
    "4000,0,0,0,inf,0,-9.81\n"
    "5000,0,0,0,0,0,-9.81\n";

TEST(SensorCsvLenientTest, StrictReadingNamesTheFileAndLineOfTheFirstBadRow) {
  test::TempDir dir;
  test::WriteTextFile(dir / "imu.csv", kImuWithBadRows);
  try {
    ReadImuCsv(dir / "imu.csv");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("imu.csv: line 4"));
  }
}

TEST(SensorCsvLenientTest, LenientReadingSkipsNonFiniteAndOutOfOrderRowsAndSaysWhich) {
  test::TempDir dir;
  test::WriteTextFile(dir / "imu.csv", kImuWithBadRows);
  std::vector<std::string> skipped;
  const std::vector<ImuSample> samples = ReadImuCsv(dir / "imu.csv", &skipped);
  ASSERT_EQ(samples.size(), 4u);
  EXPECT_EQ(samples[2].t_ns, 4000);
  EXPECT_EQ(samples[3].t_ns, 5000);
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_THAT(skipped[0], HasSubstr("line 4: NaN/Inf"));
  EXPECT_THAT(skipped[1], HasSubstr("line 6: NaN/Inf"));
}

TEST(SensorCsvLenientTest, LenientReadingStillRejectsMalformedText) {
  test::TempDir dir;
  test::WriteTextFile(dir / "imu.csv",
                      "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n1000,0,0,zero,0,0,-9.81\n");
  std::vector<std::string> skipped;
  EXPECT_THROW(ReadImuCsv(dir / "imu.csv", &skipped), InputError);
}

TEST(SensorCsvLenientTest, LenientReadingSkipsRepeatedTimestamps) {
  test::TempDir dir;
  test::WriteTextFile(dir / "depth.csv",
                      "#timestamp [ns],depth [m]\n1000,30.0\n900,30.1\n1000,30.2\n2000,30.3\n");
  std::vector<std::string> skipped;
  const std::vector<DepthMeasurement> depth = ReadDepthCsv(dir / "depth.csv", &skipped);
  ASSERT_EQ(depth.size(), 2u);
  EXPECT_EQ(depth[1].t_ns, 2000);
  ASSERT_EQ(skipped.size(), 2u);
  EXPECT_THAT(skipped[0], HasSubstr("line 3: timestamp not increasing"));
}

// The latency column of the acoustic fixes is optional (older logs: the fix arrived at once);
// a negative latency, or a row with too many columns, names the file, line and column.
TEST(SensorCsvLenientTest, AcousticLatencyIsOptionalAndMustNotBeNegative) {
  test::TempDir dir;
  test::WriteTextFile(dir / "usbl.csv",
                      "#timestamp [ns],p_D_x,p_D_y,p_D_z,sigma\n1000,1,2,3,0.05\n"
                      "2000,1,2,3,0.05,700000000\n");
  const std::vector<AcousticFix> fixes = ReadAcousticCsv(dir / "usbl.csv");
  ASSERT_EQ(fixes.size(), 2u);
  EXPECT_EQ(fixes[0].latency_ns, 0);
  EXPECT_EQ(fixes[1].latency_ns, 700000000);
  EXPECT_EQ(fixes[1].arrival_t_ns(), 700002000);
  const auto expect_error = [&](const char* row, const char* message) {
    test::WriteTextFile(dir / "usbl.csv", row);
    try {
      ReadAcousticCsv(dir / "usbl.csv");
      FAIL() << "expected InputError for " << row;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(message));
    }
  };
  expect_error("1000,1,2,3,0.05,-5\n", "usbl.csv: line 1: column 'latency': must not be negative");
  expect_error("1000,1,2,3,0.05,5,6\n", "expected 5 to 6 columns, found 7");
}

}  // namespace
}  // namespace auvdock
