// Marginal covariance of one parameter block of a Ceres problem, in the block's tangent space:
// what the sliding window reports with every output pose.
//
// At the problem's current values, with the tangent-space Jacobian J of every residual block
// (Problem::Evaluate; robust losses applied as Ceres' corrector does, so a down-weighted outlier
// contributes as little information as it did to the solve), the Gauss-Newton information is
//   H = J^T J   (n x n over all tangent coordinates),
// and the marginal covariance of block b is the b-by-b block of H^-1,
//   Sigma_bb = E_b^T H^-1 E_b,   E_b the unit columns of b's coordinates.
// H is factored once by a sparse LDL^T (Eigen's SimplicialLDLT with an AMD ordering; a window's
// H is block-tridiagonal, so this is linear in the window length) and solved for b's columns.
// It equals ceres::Covariance (SPARSE_QR) to rounding at a fraction of the cost (no QR of J).
//
// Rank deficiency: when a pivot of D is below min_relative_pivot times the largest (a gauge
// freedom, an unobserved state), no covariance is returned and `reason` says why; a caller
// reports "no covariance" instead of an unbounded or arbitrary number.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>
#include <ceres/problem.h>

namespace auvdock {

struct MarginalCovarianceOptions {
  // A pivot of D at or below this x the largest marks H as rank-deficient. H's condition number
  // in a docking window is ~1e10 (gyro-bias random walk against close-range vision).
  double min_relative_pivot = 1e-14;
};

// Sigma_bb (tangent size x tangent size, symmetric) of `block`, or std::nullopt with `reason`
// (if given) set when H is rank-deficient or the result is not finite. Throws
// std::invalid_argument if `block` is not in the problem or is held constant.
std::optional<Eigen::MatrixXd> MarginalCovariance(ceres::Problem* problem, const double* block,
                                                  const MarginalCovarianceOptions& options = {},
                                                  std::string* reason = nullptr);

}  // namespace auvdock
