#include "auvdock/io/pose_from_config.h"

#include <cmath>

namespace auvdock {

bool TransformFromRowMajor(const std::vector<double>& values, Pose3* T, std::string* why) {
  if (values.size() != 16) {
    *why = "expected 16 numbers (a row-major 4x4 transform), got " + std::to_string(values.size());
    return false;
  }
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) M(r, c) = values[4 * r + c];
  }
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    *why = "last row must be 0 0 0 1";
    return false;
  }
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
      std::abs(R.determinant() - 1.0) > 1e-6) {
    *why = "rotation block is not a rotation (orthonormal, determinant +1)";
    return false;
  }
  *T = Pose3::FromMatrix(M);
  return true;
}

Pose3 GetTransform(const ConfigNode& node, const std::string& key) {
  Pose3 T;
  std::string why;
  if (!TransformFromRowMajor(node.GetDoubles(key), &T, &why)) node.Fail(key, why);
  return T;
}

Pose3 GetTransform(const ConfigNode& node, const std::string& key, const Pose3& fallback) {
  return node.Has(key) ? GetTransform(node, key) : fallback;
}

}  // namespace auvdock
