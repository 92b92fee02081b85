#include "auvdock/vision/point_set_alignment.h"

#include <cmath>

#include <Eigen/SVD>

namespace auvdock {
namespace {

// Second singular value of H relative to the first below which the points count as collinear.
// H's singular values are squared lengths, so 1e-12 means a spread across the line of ~1e-6
// of the spread along it: below that the rotation about the line is set by round-off.
constexpr double kCollinearTolerance = 1e-12;

AlignmentResult Fail(const std::string& reason) {
  AlignmentResult result;
  result.reason = reason;
  return result;
}

}  // namespace

AlignmentResult AlignPointSets(const std::vector<Eigen::Vector3d>& src,
                               const std::vector<Eigen::Vector3d>& dst,
                               const std::vector<double>& weights) {
  const size_t n = src.size();
  if (dst.size() != n) return Fail("size mismatch between src and dst");
  if (!weights.empty() && weights.size() != n)
    return Fail("size mismatch between points and weights");
  if (n < 3) return Fail("fewer than 3 points");
  for (size_t i = 0; i < n; ++i) {
    if (!src[i].allFinite() || !dst[i].allFinite()) return Fail("NaN or Inf coordinate");
  }
  int n_positive = 0;
  double weight_sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    if (!std::isfinite(w)) return Fail("NaN or Inf weight");
    if (w < 0.0) return Fail("negative weight");
    if (w > 0.0) ++n_positive;
    weight_sum += w;
  }
  if (n_positive < 3) return Fail("fewer than 3 points with positive weight");

  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d q0 = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    p0 += w * src[i];
    q0 += w * dst[i];
  }
  p0 /= weight_sum;
  q0 /= weight_sum;

  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    H += w * (src[i] - p0) * (dst[i] - q0).transpose();
  }
  H /= weight_sum;  // scale-free; keeps the tolerance test independent of the weights' units

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d& s = svd.singularValues();  // descending
  if (!(s(0) > 0.0) || s(1) <= kCollinearTolerance * s(0)) {
    return Fail("points are collinear or coincident: rotation about their line is free");
  }
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Vector3d d(1.0, 1.0, 1.0);
  d(2) = (V * U.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d R = V * d.asDiagonal() * U.transpose();
  const Eigen::Vector3d T = q0 - R * p0;

  AlignmentResult result;
  result.ok = true;
  result.T_dst_src = Pose3(Eigen::Quaterniond(R), T);
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double w = weights.empty() ? 1.0 : weights[i];
    sum += w * (R * src[i] + T - dst[i]).squaredNorm();
  }
  result.rms_m = std::sqrt(sum / weight_sum);
  return result;
}

}  // namespace auvdock
