#include "auvdock/io/tum_io.h"

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/input_error.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

class TumIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("auvdock_tum_io_test_" + std::to_string(::getpid()) + "_" + info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::string PathOf(const std::string& name) const { return (dir_ / name).string(); }

  std::string WriteText(const std::string& name, const std::string& text) const {
    const std::string path = PathOf(name);
    std::ofstream(path) << text;
    return path;
  }

  // The message of the InputError that reading `path` raises ("" and a failure if none).
  static std::string ReadError(const std::string& path) {
    try {
      ReadTumTrajectory(path);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "reading " << path << " did not throw InputError";
    return "";
  }

  std::filesystem::path dir_;
};

Trajectory RandomTrajectory(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> position(-50.0, 50.0);
  std::uniform_int_distribution<int64_t> step(1, 50'000'000);
  Trajectory trajectory;
  int64_t t_ns = 1'700'000'000'123'456'789;
  for (int i = 0; i < n; ++i) {
    StampedPose pose;
    pose.t_ns = t_ns;
    t_ns += step(rng);
    pose.T_D_B = Pose3(Eigen::Quaterniond::UnitRandom(),
                       Eigen::Vector3d(position(rng), position(rng), position(rng)) / 3.0);
    trajectory.push_back(pose);
  }
  return trajectory;
}

void ExpectSameTrajectory(const Trajectory& expected, const Trajectory& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(expected[i].t_ns, actual[i].t_ns) << "pose " << i;
    EXPECT_LE((expected[i].T_D_B.p - actual[i].T_D_B.p).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LE((expected[i].T_D_B.q.coeffs() - actual[i].T_D_B.q.coeffs()).cwiseAbs().maxCoeff(),
              1e-9);
  }
}

TEST_F(TumIoTest, WriteThenReadIsIdentity) {
  const Trajectory trajectory = RandomTrajectory(500, 7);
  const std::string path = PathOf("traj.tum");
  WriteTumTrajectory(path, trajectory);
  ExpectSameTrajectory(trajectory, ReadTumTrajectory(path));
}

// The rows of `path` as evo's readers see them (evo/tools/file_interface.py:
// read_tum_trajectory_file, read_euroc_csv_trajectory): lines starting with '#' are skipped, the
// rest split at every single delimiter (csv.reader: two spaces make an empty field, a trailing
// one a last empty field), and each field must convert to a float (numpy astype(float)).
std::vector<std::vector<double>> ReadAsEvoDoes(const std::string& path, char delimiter) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind('#', 0) == 0) continue;
    std::vector<double> row;
    size_t start = 0;
    while (true) {
      const size_t end = line.find(delimiter, start);
      const std::string field = line.substr(start, end - start);
      char* parsed_to = nullptr;
      const double value = std::strtod(field.c_str(), &parsed_to);
      EXPECT_TRUE(!field.empty() && *parsed_to == '\0') << path << ": field '" << field << "'";
      row.push_back(value);
      if (end == std::string::npos) break;
      start = end + 1;
    }
    rows.push_back(row);
  }
  return rows;
}

TEST_F(TumIoTest, EvoReadsTheFileAsItIs) {
  const Trajectory trajectory = RandomTrajectory(50, 3);
  const std::string path = PathOf("traj.tum");
  WriteTumTrajectory(path, trajectory);
  const std::vector<std::vector<double>> rows = ReadAsEvoDoes(path, ' ');
  ASSERT_EQ(rows.size(), trajectory.size());  // the header is a '#' line, no blank lines
  for (size_t i = 0; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), 8u) << "row " << i;  // t x y z qx qy qz qw
    EXPECT_NEAR(rows[i][0], 1e-9 * static_cast<double>(trajectory[i].t_ns), 1e-6);  // seconds
    EXPECT_NEAR(rows[i][1], trajectory[i].T_D_B.p.x(), 1e-12);
    EXPECT_NEAR(std::abs(rows[i][7]), std::abs(trajectory[i].T_D_B.q.w()), 1e-12);  // w last
  }
}

TEST_F(TumIoTest, NegativeAndZeroTimesRoundTrip) {
  Trajectory trajectory(3);
  trajectory[0].t_ns = -1'500'000'001;
  trajectory[1].t_ns = -1;
  trajectory[2].t_ns = 0;
  const std::string path = PathOf("traj.tum");
  WriteTumTrajectory(path, trajectory);
  ExpectSameTrajectory(trajectory, ReadTumTrajectory(path));
}

TEST_F(TumIoTest, StreamingWriterFlushesEveryLine) {
  const Trajectory trajectory = RandomTrajectory(5, 11);
  const std::string path = PathOf("stream.tum");
  TumWriter writer(path);
  EXPECT_EQ(writer.path(), path);
  for (size_t i = 0; i < trajectory.size(); ++i) {
    writer.Append(trajectory[i]);
    // Readable while the writer is still open: every appended line is on disk.
    const Trajectory so_far = ReadTumTrajectory(path);
    ASSERT_EQ(so_far.size(), i + 1);
  }
  EXPECT_EQ(writer.num_poses(), 5);
  ExpectSameTrajectory(trajectory, ReadTumTrajectory(path));
}

TEST_F(TumIoTest, WriterRefusesUnwritablePath) {
  const std::string path = PathOf("no_such_dir/traj.tum");
  EXPECT_THROW(TumWriter{path}, InputError);
  EXPECT_THROW(WriteTumTrajectory(path, Trajectory()), InputError);
}

TEST_F(TumIoTest, ParsesTimestampsExactly) {
  const std::string path = WriteText("exact.tum",
                                     "1700000000.123456789 1 2 3 0 0 0 1\n"
                                     "1700000000.123456790 1 2 3 0 0 0 1\n"
                                     "1700000001 1 2 3 0 0 0 1\n"
                                     "1700000001.5e0 1 2 3 0 0 0 1\n");
  const Trajectory trajectory = ReadTumTrajectory(path);
  ASSERT_EQ(trajectory.size(), 4u);
  EXPECT_EQ(trajectory[0].t_ns, 1700000000123456789);
  EXPECT_EQ(trajectory[1].t_ns, 1700000000123456790);
  EXPECT_EQ(trajectory[2].t_ns, 1700000001000000000);
  EXPECT_EQ(trajectory[3].t_ns, 1700000001500000000);
}

TEST(ParseSecondsToNanosecondsTest, ExactDecimalArithmetic) {
  struct Case {
    const char* text;
    int64_t t_ns;
  };
  const Case cases[] = {
      {"0", 0},
      {"12", 12'000'000'000},
      {"12.", 12'000'000'000},
      {".5", 500'000'000},
      {"+3.25", 3'250'000'000},
      {"-0.000000001", -1},
      {"1700000000.123456789", 1'700'000'000'123'456'789},
      {"0001700000000.1234567890000", 1'700'000'000'123'456'789},
      {"1.7e9", 1'700'000'000'000'000'000},
      {"1.7E+9", 1'700'000'000'000'000'000},
      {"1700000000123456789e-9", 1'700'000'000'123'456'789},
      {"0.0000000005", 1},      // half a nanosecond rounds away from zero
      {"0.00000000049999", 0},  // below half rounds down
      {"-0.0000000015", -2},
      {"1.2345678994", 1'234'567'899},
      {"1.2345678995", 1'234'567'900},
      {"1e-30", 0},
      {"0e400", 0},
      {"9223372036.854775807", std::numeric_limits<int64_t>::max()},
      {"-9223372036.854775808", std::numeric_limits<int64_t>::min()},
  };
  for (const Case& c : cases) {
    int64_t t_ns = -42;
    EXPECT_TRUE(ParseSecondsToNanoseconds(c.text, &t_ns)) << c.text;
    EXPECT_EQ(t_ns, c.t_ns) << c.text;
  }
}

TEST(ParseSecondsToNanosecondsTest, RejectsNonNumbersAndOverflow) {
  for (const char* text : {"",
                           ".",
                           "-",
                           "+",
                           "abc",
                           "1.2.3",
                           "1,5",
                           "nan",
                           "NaN",
                           "inf",
                           "-inf",
                           "1e",
                           "1e+",
                           "--1",
                           "+-1",
                           "0x10",
                           "1 ",
                           " 1",
                           "9223372036.854775808",
                           "1e10",
                           "-9223372036.8547758085",
                           "99999999999999999999"}) {
    int64_t t_ns = 0;
    EXPECT_FALSE(ParseSecondsToNanoseconds(text, &t_ns)) << "'" << text << "'";
  }
}

TEST(FormatNanosecondsAsSecondsTest, NineExactDecimals) {
  EXPECT_EQ(FormatNanosecondsAsSeconds(0), "0.000000000");
  EXPECT_EQ(FormatNanosecondsAsSeconds(1'500'000'001), "1.500000001");
  EXPECT_EQ(FormatNanosecondsAsSeconds(-1), "-0.000000001");
  EXPECT_EQ(FormatNanosecondsAsSeconds(1'700'000'000'123'456'789), "1700000000.123456789");
  EXPECT_EQ(FormatNanosecondsAsSeconds(std::numeric_limits<int64_t>::min()),
            "-9223372036.854775808");
}

TEST_F(TumIoTest, SkipsCommentsAndBlankLinesAndAcceptsCrLf) {
  const std::string path = WriteText("comments.tum",
                                     "# t tx ty tz qx qy qz qw\n"
                                     "\n"
                                     "   \t\n"
                                     "  # indented comment\n"
                                     "1.0 1 2 3 0 0 0 1\r\n"
                                     "2.0\t4 5 6   0 0 1 0\r\n");
  const Trajectory trajectory = ReadTumTrajectory(path);
  ASSERT_EQ(trajectory.size(), 2u);
  EXPECT_EQ(trajectory[1].t_ns, 2'000'000'000);
  EXPECT_EQ(trajectory[1].T_D_B.p, Eigen::Vector3d(4, 5, 6));
  // TUM order is qx qy qz qw: "0 0 1 0" is a half turn about z.
  EXPECT_DOUBLE_EQ(trajectory[1].T_D_B.q.z(), 1.0);
  EXPECT_DOUBLE_EQ(trajectory[1].T_D_B.q.w(), 0.0);
}

TEST_F(TumIoTest, NormalizesQuaternions) {
  const std::string path = WriteText("norm.tum", "1 0 0 0 0 0 0 2\n");
  const Trajectory trajectory = ReadTumTrajectory(path);
  ASSERT_EQ(trajectory.size(), 1u);
  EXPECT_DOUBLE_EQ(trajectory[0].T_D_B.q.w(), 1.0);
}

TEST_F(TumIoTest, EmptyFileGivesEmptyTrajectory) {
  EXPECT_TRUE(ReadTumTrajectory(WriteText("empty.tum", "")).empty());
  EXPECT_TRUE(ReadTumTrajectory(WriteText("header.tum", "# only a header\n")).empty());
}

TEST_F(TumIoTest, MissingFileNamesTheFile) {
  const std::string path = PathOf("missing.tum");
  EXPECT_THAT(ReadError(path), HasSubstr(path));
  EXPECT_THAT(ReadError(dir_.string()), HasSubstr(dir_.string()));
}

TEST_F(TumIoTest, WrongColumnCountNamesPathAndLine) {
  const std::string path = WriteText("columns.tum",
                                     "# header\n"
                                     "1 0 0 0 0 0 0 1\n"
                                     "2 0 0 0 0 0 1\n");
  const std::string message = ReadError(path);
  EXPECT_THAT(message, HasSubstr(path + ": line 3: "));
  EXPECT_THAT(message, HasSubstr("expected 8 columns"));
  EXPECT_THAT(ReadError(WriteText("extra.tum", "1 0 0 0 0 0 0 1 9\n")), HasSubstr("line 1: "));
}

TEST_F(TumIoTest, NonNumberNamesPathLineAndColumn) {
  const std::string path = WriteText("word.tum", "1 0 0 0 0 0 0 1\n\n2 0 zero 0 0 0 0 1\n");
  const std::string message = ReadError(path);
  EXPECT_THAT(message, HasSubstr(path + ": line 3: "));
  EXPECT_THAT(message, HasSubstr("ty"));
  EXPECT_THAT(message, HasSubstr("zero"));
  EXPECT_THAT(ReadError(WriteText("time.tum", "1.5s 0 0 0 0 0 0 1\n")),
              HasSubstr("line 1: timestamp '1.5s'"));
}

TEST_F(TumIoTest, RejectsNanAndInf) {
  const std::string path = WriteText("nan.tum", "1 0 0 0 0 0 0 1\n2 0 0 nan 0 0 0 1\n");
  const std::string message = ReadError(path);
  EXPECT_THAT(message, HasSubstr(path + ": line 2: "));
  EXPECT_THAT(message, HasSubstr("not finite"));
  EXPECT_THAT(ReadError(WriteText("inf.tum", "1 0 0 0 0 0 0 -inf\n")), HasSubstr("line 1: "));
  EXPECT_THAT(ReadError(WriteText("nan_t.tum", "nan 0 0 0 0 0 0 1\n")),
              HasSubstr("line 1: timestamp"));
}

TEST_F(TumIoTest, RejectsZeroQuaternion) {
  const std::string path = WriteText("zero_q.tum", "1 0 0 0 0 0 0 0\n");
  const std::string message = ReadError(path);
  EXPECT_THAT(message, HasSubstr(path + ": line 1: "));
  EXPECT_THAT(message, HasSubstr("quaternion"));
}

TEST_F(TumIoTest, RejectsNonIncreasingTimestamps) {
  const std::string equal = WriteText("equal.tum",
                                      "1.000000001 0 0 0 0 0 0 1\n"
                                      "1.0000000010 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(equal), HasSubstr(equal + ": line 2: "));
  EXPECT_THAT(ReadError(equal), HasSubstr("not after the previous"));
  const std::string decreasing = WriteText("decreasing.tum",
                                           "1 0 0 0 0 0 0 1\n"
                                           "# comment\n"
                                           "3 0 0 0 0 0 0 1\n"
                                           "2 0 0 0 0 0 0 1\n");
  EXPECT_THAT(ReadError(decreasing), HasSubstr(decreasing + ": line 4: "));
}

}  // namespace
}  // namespace auvdock
