// The pose-covariance file written by `auvdock run` / `smooth` (covariance.csv) and read by
// `auvdock evaluate --covariance`.
//
// One header line, then one row per output pose that has a covariance:
//   timestamp_ns, c00, c01, ..., c55
// the 6x6 covariance row-major in the PoseManifold tangent space [dp_D x y z (m), dtheta_D x y z
// (rad)], i.e. T_D_B = (p + dp, Exp(dtheta) q): position in the dock frame D, attitude as a
// rotation vector applied on the left, in D (factors/pose_manifold.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace auvdock {

struct StampedPoseCovariance {
  int64_t t_ns = 0;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// The header line, which also says the order and the frame of the tangent space.
std::string PoseCovarianceCsvHeader();

// The 36 values of a row after its timestamp (row-major).
std::vector<double> PoseCovarianceCsvValues(const Eigen::Matrix<double, 6, 6>& covariance);

// Reads a covariance file. Throws InputError naming the file and line on a malformed row, a
// non-finite value, a timestamp that does not increase, or a matrix that is not symmetric
// (to 1e-9 relative) and positive definite.
std::vector<StampedPoseCovariance> ReadPoseCovarianceCsv(const std::string& path);

}  // namespace auvdock
