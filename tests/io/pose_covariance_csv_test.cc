#include "auvdock/io/pose_covariance_csv.h"

#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/io/csv.h"
#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

Eigen::Matrix<double, 6, 6> SomeCovariance(double scale) {
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Identity();
  A(1, 0) = 0.4;
  A(5, 3) = -0.25;
  return scale * A * A.transpose();
}

void WriteRows(const std::string& path, const std::vector<StampedPoseCovariance>& rows) {
  CsvWriter writer(path, PoseCovarianceCsvHeader());
  for (const StampedPoseCovariance& row : rows) {
    writer.Row(row.t_ns, PoseCovarianceCsvValues(row.covariance));
  }
}

TEST(PoseCovarianceCsvTest, ValuesAreRowMajorAsTheHeaderSays) {
  Eigen::Matrix<double, 6, 6> m;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) m(r, c) = 10 * r + c;
  }
  const std::vector<double> values = PoseCovarianceCsvValues(m);
  ASSERT_EQ(values.size(), 36u);
  EXPECT_EQ(values[1], 1.0);    // c01
  EXPECT_EQ(values[6], 10.0);   // c10
  EXPECT_EQ(values[35], 55.0);  // c55
  EXPECT_THAT(PoseCovarianceCsvHeader(), HasSubstr(",c00,c01,"));
}

std::string ReadError(const std::string& path) {
  try {
    ReadPoseCovarianceCsv(path);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(PoseCovarianceCsvTest, WriteThenReadIsIdentity) {
  const test::TempDir dir;
  const std::vector<StampedPoseCovariance> rows = {{100, SomeCovariance(1e-4)},
                                                   {200, SomeCovariance(3.7e-6)}};
  WriteRows(dir / "covariance.csv", rows);
  const std::vector<StampedPoseCovariance> read = ReadPoseCovarianceCsv(dir / "covariance.csv");
  ASSERT_EQ(read.size(), rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(read[k].t_ns, rows[k].t_ns);
    EXPECT_EQ(read[k].covariance, rows[k].covariance);  // bit-exact
  }
}

TEST(PoseCovarianceCsvTest, BadRowsNameTheFileAndLine) {
  const test::TempDir dir;
  const std::string path = dir / "covariance.csv";
  Eigen::Matrix<double, 6, 6> asymmetric = SomeCovariance(1.0);
  asymmetric(0, 5) += 0.1;
  WriteRows(path, {{100, SomeCovariance(1.0)}, {200, asymmetric}});
  EXPECT_THAT(ReadError(path),
              HasSubstr("covariance.csv: line 3: the covariance is not symmetric"));

  Eigen::Matrix<double, 6, 6> indefinite = SomeCovariance(1.0);
  indefinite(2, 2) = -1.0;
  WriteRows(path, {{100, indefinite}});
  EXPECT_THAT(ReadError(path), HasSubstr("line 2: the covariance is not positive definite"));

  WriteRows(path, {{200, SomeCovariance(1.0)}, {200, SomeCovariance(1.0)}});
  EXPECT_THAT(ReadError(path), HasSubstr("line 3: timestamp 200 is not after"));

  {
    std::ofstream out(path);
    out << PoseCovarianceCsvHeader() << "\n100,1,0,0\n";
  }
  EXPECT_THAT(ReadError(path), HasSubstr("line 2"));
  {
    std::ofstream out(path);
    out << PoseCovarianceCsvHeader() << "\n100";
    for (int k = 0; k < 36; ++k) out << (k == 7 ? ",nan" : ",1");
    out << "\n";
  }
  EXPECT_THAT(ReadError(path), HasSubstr("line 2: column 'c11'"));
}

}  // namespace
}  // namespace auvdock
