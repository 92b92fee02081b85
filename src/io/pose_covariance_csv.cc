#include "auvdock/io/pose_covariance_csv.h"

#include <Eigen/Cholesky>

#include "auvdock/io/csv.h"

namespace auvdock {

std::vector<double> PoseCovarianceCsvValues(const Eigen::Matrix<double, 6, 6>& covariance) {
  const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> row_major = covariance;
  return std::vector<double>(row_major.data(), row_major.data() + 36);
}

std::string PoseCovarianceCsvHeader() {
  std::string header = "#timestamp [ns]";
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) header += ",c" + std::to_string(r) + std::to_string(c);
  }
  return header +
         " (6x6 row-major; tangent [dp_D x y z (m), dtheta_D x y z (rad)]; "
         "T_D_B = (p + dp, Exp(dtheta) q))";
}

std::vector<StampedPoseCovariance> ReadPoseCovarianceCsv(const std::string& path) {
  std::vector<std::string> columns = {"timestamp"};
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) columns.push_back("c" + std::to_string(r) + std::to_string(c));
  }
  CsvReader reader(path, columns);
  std::vector<StampedPoseCovariance> rows;
  while (reader.Next()) {
    StampedPoseCovariance row;
    row.t_ns = reader.Int64(0);
    CheckIncreasingTime(reader, rows.empty() ? INT64_MIN : rows.back().t_ns, row.t_ns);
    for (int k = 0; k < 36; ++k) row.covariance(k / 6, k % 6) = reader.Double(1 + k);
    const double scale = row.covariance.cwiseAbs().maxCoeff();
    if ((row.covariance - row.covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
      reader.Fail("the covariance is not symmetric");
    }
    if (!(scale > 0.0) || Eigen::LLT<Eigen::Matrix<double, 6, 6>>(row.covariance).info() !=
                              Eigen::Success) {
      reader.Fail("the covariance is not positive definite");
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace auvdock
