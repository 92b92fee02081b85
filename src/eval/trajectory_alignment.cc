#include "auvdock/eval/trajectory_alignment.h"

#include <cassert>

#include <Eigen/SVD>

#include "auvdock/io/input_error.h"

namespace auvdock {
namespace {

// Relative size of the second singular value of the cross-covariance below which the points
// count as collinear: exactly collinear doubles give ~1e-16, and at 1e-10 the rotation about
// the line would be fixed by round-off alone.
constexpr double kCollinearTolerance = 1e-10;

[[noreturn]] void ThrowDegenerate() {
  throw InputError("SE(3) alignment needs at least 3 non-collinear positions");
}

}  // namespace

Pose3 AlignPositionsSE3(const std::vector<Eigen::Vector3d>& p_est,
                        const std::vector<Eigen::Vector3d>& p_true) {
  assert(p_est.size() == p_true.size());
  const size_t n = p_est.size();
  if (n < 3) ThrowDegenerate();

  Eigen::Vector3d mu_est = Eigen::Vector3d::Zero();
  Eigen::Vector3d mu_true = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    mu_est += p_est[i];
    mu_true += p_true[i];
  }
  mu_est /= static_cast<double>(n);
  mu_true /= static_cast<double>(n);

  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    sigma += (p_true[i] - mu_true) * (p_est[i] - mu_est).transpose();
  }
  sigma /= static_cast<double>(n);

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d& d = svd.singularValues();  // sorted, largest first
  if (!(d(0) > 0.0) || d(1) <= kCollinearTolerance * d(0)) ThrowDegenerate();

  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Vector3d s(1.0, 1.0, 1.0);
  if (U.determinant() * V.determinant() < 0.0) s(2) = -1.0;
  const Eigen::Matrix3d R = U * s.asDiagonal() * V.transpose();
  const Eigen::Vector3d t = mu_true - R * mu_est;
  return Pose3(Eigen::Quaterniond(R), t);
}

}  // namespace auvdock
