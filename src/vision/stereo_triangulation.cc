#include "auvdock/vision/stereo_triangulation.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>

#include <Eigen/Dense>

#include "auvdock/geometry/so3.h"

namespace auvdock {
namespace {

// Parallax (in pixels of the left camera) below which the rays count as parallel, when the
// pixel noise is smaller than this.
constexpr double kMinParallaxPx = 0.05;
// Search-tree nodes allowed per connected group of match candidates before the matcher falls
// back to mutual best pairs (a group of 6 lights with 3 candidates each needs a few hundred).
constexpr int kMaxSearchNodes = 200000;

// The pair's relative pose and the quantities every triangulation and match needs.
struct StereoGeometry {
  Eigen::Matrix3d R;             // R_R_L
  Eigen::Vector3d t;             // t_R_L: x_R = R x_S + t
  Eigen::Matrix3d E;             // essential matrix [t]x R: x_R^T E x_L = 0
  Eigen::Vector3d baseline_dir;  // unit vector from the left to the right centre, in S
};

StereoGeometry MakeGeometry(const CameraCalibration& left, const CameraCalibration& right) {
  const Pose3 T_R_L = right.T_B_C.Inverse() * left.T_B_C;
  StereoGeometry g;
  g.R = T_R_L.R();
  g.t = T_R_L.p;
  g.E = Hat(g.t) * g.R;
  g.baseline_dir = (-g.R.transpose() * g.t).normalized();
  return g;
}

struct LinearSystem {
  Eigen::Matrix<double, 4, 3> A;
  Eigen::Vector4d b;
};

// Seed 000 eqs. 14-15 with the left camera at the origin of S.
LinearSystem BuildSystem(const Eigen::Vector2d& xy_l, const Eigen::Vector2d& xy_r,
                         const StereoGeometry& g) {
  LinearSystem s;
  s.A.row(0) << -1.0, 0.0, xy_l.x();
  s.A.row(1) << 0.0, -1.0, xy_l.y();
  s.b(0) = 0.0;
  s.b(1) = 0.0;
  s.A.row(2) = xy_r.x() * g.R.row(2) - g.R.row(0);
  s.A.row(3) = xy_r.y() * g.R.row(2) - g.R.row(1);
  s.b(2) = g.t(0) - xy_r.x() * g.t(2);
  s.b(3) = g.t(1) - xy_r.y() * g.t(2);
  return s;
}

Eigen::Vector3d SolveSystem(const LinearSystem& s) { return s.A.colPivHouseholderQr().solve(s.b); }

// d(x', y') / d(u, v): inverse of the projection's Jacobian at the undistorted point, the
// latter by central differences (the map is a low-order polynomial: h = 1e-6 is exact to
// ~1e-12 relative).
Eigen::Matrix2d UndistortJacobian(const PinholeRadtanCamera& camera, const Eigen::Vector2d& xy) {
  const double h = 1e-6;
  Eigen::Matrix2d J_uv_xy;
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector2d plus = xy, minus = xy;
    plus(k) += h;
    minus(k) -= h;
    J_uv_xy.col(k) = (camera.ProjectNormalized(plus) - camera.ProjectNormalized(minus)) / (2 * h);
  }
  return J_uv_xy.inverse();
}

// Angle between a ray (in S) and the baseline direction.
double BaselineAngle(const Eigen::Vector3d& ray_S, const Eigen::Vector3d& baseline_dir) {
  return std::atan2(ray_S.cross(baseline_dir).norm(), ray_S.dot(baseline_dir));
}

TriangulatedPoint Fail(const std::string& reason) {
  TriangulatedPoint point;
  point.reason = reason;
  return point;
}

}  // namespace

TriangulatedPoint TriangulateLinear(const Eigen::Vector2d& uv_left, const Eigen::Vector2d& uv_right,
                                    const CameraCalibration& left, const CameraCalibration& right,
                                    double pixel_sigma) {
  if (!uv_left.allFinite() || !uv_right.allFinite()) return Fail("NaN or Inf pixel");
  if (!(pixel_sigma > 0.0) || !std::isfinite(pixel_sigma)) {
    return Fail("pixel_sigma must be positive and finite");
  }
  const StereoGeometry g = MakeGeometry(left, right);
  const Eigen::Vector2d xy_l = left.intrinsics.Unproject(uv_left);
  const Eigen::Vector2d xy_r = right.intrinsics.Unproject(uv_right);
  if (!xy_l.allFinite() || !xy_r.allFinite()) return Fail("pixel cannot be undistorted");

  const Eigen::Vector3d ray_l = xy_l.homogeneous().normalized();
  const Eigen::Vector3d ray_r_in_S = g.R.transpose() * xy_r.homogeneous().normalized();
  const double parallax = std::atan2(ray_l.cross(ray_r_in_S).norm(), ray_l.dot(ray_r_in_S));
  if (parallax * left.intrinsics.fx() < std::max(pixel_sigma, kMinParallaxPx)) {
    return Fail("parallel rays: negligible disparity");
  }

  const LinearSystem s = BuildSystem(xy_l, xy_r, g);
  const Eigen::Vector3d X = SolveSystem(s);
  if (!X.allFinite()) return Fail("degenerate linear system");
  const Eigen::Vector3d X_R = g.R * X + g.t;
  if (!(X.z() > 0.0)) return Fail("point behind the left camera");
  if (!(X_R.z() > 0.0)) return Fail("point behind the right camera");

  // dX / d(x'_l, y'_l, x'_r, y'_r) = -(A^T A)^-1 (r3 e_k + a_k z_c), see the header.
  const Eigen::Matrix3d AtA_inverse = (s.A.transpose() * s.A).inverse();
  const Eigen::Vector4d e = s.A * X - s.b;
  Eigen::Matrix<double, 3, 4> J_X_xy;
  for (int k = 0; k < 4; ++k) {
    const bool in_left = k < 2;
    const Eigen::Vector3d r3 = in_left ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d(g.R.row(2));
    const double depth = in_left ? X.z() : X_R.z();
    J_X_xy.col(k) = -AtA_inverse * (r3 * e(k) + s.A.row(k).transpose() * depth);
  }
  Eigen::Matrix4d J_xy_uv = Eigen::Matrix4d::Zero();
  J_xy_uv.topLeftCorner<2, 2>() = UndistortJacobian(left.intrinsics, xy_l);
  J_xy_uv.bottomRightCorner<2, 2>() = UndistortJacobian(right.intrinsics, xy_r);
  const Eigen::Matrix<double, 3, 4> J = J_X_xy * J_xy_uv;

  TriangulatedPoint point;
  point.ok = true;
  point.p_S = X;
  point.covariance = pixel_sigma * pixel_sigma * J * J.transpose();
  const Eigen::Vector2d r_l = left.intrinsics.ProjectNormalized(X.head<2>() / X.z()) - uv_left;
  const Eigen::Vector2d r_r =
      right.intrinsics.ProjectNormalized(X_R.head<2>() / X_R.z()) - uv_right;
  point.reprojection_rms_px = std::sqrt(0.5 * (r_l.squaredNorm() + r_r.squaredNorm()));
  return point;
}

std::vector<std::pair<int, int>> MatchStereoDetections(const std::vector<LightDetection>& left,
                                                       const std::vector<LightDetection>& right,
                                                       const CameraCalibration& left_cal,
                                                       const CameraCalibration& right_cal,
                                                       const StereoMatchOptions& options) {
  const int n_left = static_cast<int>(left.size());
  const int n_right = static_cast<int>(right.size());
  const StereoGeometry g = MakeGeometry(left_cal, right_cal);
  const double f_right = std::sqrt(right_cal.intrinsics.fx() * right_cal.intrinsics.fy());

  // Undistorted normalized coordinates and angles to the baseline (ordering constraint).
  auto prepare = [&](const std::vector<LightDetection>& detections, const CameraCalibration& cal,
                     const Eigen::Matrix3d& R_S_C, std::vector<Eigen::Vector2d>* xy,
                     std::vector<double>* phi, std::vector<bool>* valid) {
    const size_t n = detections.size();
    xy->resize(n);
    phi->resize(n);
    valid->assign(n, false);
    for (size_t i = 0; i < n; ++i) {
      if (!detections[i].uv.allFinite()) continue;
      (*xy)[i] = cal.intrinsics.Unproject(detections[i].uv);
      if (!(*xy)[i].allFinite()) continue;
      (*phi)[i] = BaselineAngle(R_S_C * (*xy)[i].homogeneous(), g.baseline_dir);
      (*valid)[i] = true;
    }
  };
  std::vector<Eigen::Vector2d> xy_l, xy_r;
  std::vector<double> phi_l, phi_r;
  std::vector<bool> valid_l, valid_r;
  prepare(left, left_cal, Eigen::Matrix3d::Identity(), &xy_l, &phi_l, &valid_l);
  prepare(right, right_cal, g.R.transpose(), &xy_r, &phi_r, &valid_r);

  // Gates and costs of every pair.
  std::vector<std::vector<bool>> epipolar_ok(n_left, std::vector<bool>(n_right, false));
  std::vector<std::vector<int>> candidates_of_left(n_left);
  std::vector<std::vector<double>> cost(
      n_left, std::vector<double>(n_right, std::numeric_limits<double>::infinity()));
  const double log_ratio_gate = std::log(std::max(options.max_radius_ratio, 1.0 + 1e-9));
  for (int i = 0; i < n_left; ++i) {
    if (!valid_l[i]) continue;
    const Eigen::Vector3d line = g.E * xy_l[i].homogeneous();
    const double line_norm = line.head<2>().norm();
    for (int j = 0; j < n_right; ++j) {
      if (!valid_r[j] || !(line_norm > 0.0)) continue;
      const double distance_px = std::abs(xy_r[j].homogeneous().dot(line)) / line_norm * f_right;
      if (!(distance_px <= options.epipolar_gate_px)) continue;
      epipolar_ok[i][j] = true;

      const double r_l = left[i].radius_px;
      const double r_r = right[j].radius_px;
      double radius_term = 0.0;
      if (r_l > 0.0 && r_r > 0.0) {
        const double log_ratio = std::abs(std::log(r_l / r_r));
        if (!(log_ratio <= log_ratio_gate)) continue;
        radius_term = log_ratio / log_ratio_gate;
      }
      const Eigen::Vector3d X = SolveSystem(BuildSystem(xy_l[i], xy_r[j], g));
      const double z_right = g.R.row(2).dot(X) + g.t(2);
      if (!X.allFinite() || !(X.z() > 0.0) || !(z_right > 0.0)) continue;
      if (X.z() < options.min_depth_m || X.z() > options.max_depth_m) continue;
      if (!(phi_r[j] > phi_l[i])) continue;  // rays diverge: negative disparity
      const double epipolar_term = distance_px / options.epipolar_gate_px;
      cost[i][j] = epipolar_term * epipolar_term + radius_term * radius_term;
      candidates_of_left[i].push_back(j);
    }
  }

  // Connected groups of candidates (union-find over left i and right n_left + j).
  std::vector<int> parent(n_left + n_right);
  std::iota(parent.begin(), parent.end(), 0);
  std::function<int(int)> find = [&](int a) {
    return parent[a] == a ? a : parent[a] = find(parent[a]);
  };
  for (int i = 0; i < n_left; ++i) {
    for (int j : candidates_of_left[i]) parent[find(i)] = find(n_left + j);
  }

  // Two pairs may coexist unless their left points share an epipolar line and they cross.
  auto compatible = [&](int i, int j, int k, int l) {
    if (i == k || j == l) return false;
    if (!(epipolar_ok[i][l] && epipolar_ok[k][j])) return true;
    return (phi_l[i] - phi_l[k]) * (phi_r[j] - phi_r[l]) > 0.0;
  };

  std::vector<std::pair<int, int>> matches;
  std::vector<bool> group_done(n_left + n_right, false);
  for (int seed = 0; seed < n_left; ++seed) {
    if (candidates_of_left[seed].empty()) continue;
    const int root = find(seed);
    if (group_done[root]) continue;
    group_done[root] = true;
    std::vector<int> group;  // left detections of this group
    for (int i = 0; i < n_left; ++i) {
      if (!candidates_of_left[i].empty() && find(i) == root) group.push_back(i);
    }

    // Exhaustive search over the group's left detections: pass 1 finds the best (most pairs,
    // then least cost); pass 2 visits every assignment as good within the margin.
    const int m = static_cast<int>(group.size());
    std::vector<std::pair<int, int>> chosen;
    int nodes = 0;
    int best_count = -1;
    double best_cost = std::numeric_limits<double>::infinity();
    std::vector<std::pair<int, int>> best;
    std::vector<std::pair<int, int>> common;
    bool second_pass = false;
    std::function<void(int, double)> search = [&](int index, double cost_so_far) {
      if (++nodes > kMaxSearchNodes) return;
      const int count = static_cast<int>(chosen.size());
      if (second_pass) {
        if (count + (m - index) < best_count) return;
        if (cost_so_far > best_cost + options.ambiguity_margin) return;
      }
      if (index == m) {
        if (!second_pass) {
          if (count > best_count || (count == best_count && cost_so_far < best_cost)) {
            best_count = count;
            best_cost = cost_so_far;
            best = chosen;
          }
        } else if (count == best_count) {
          std::vector<std::pair<int, int>> kept;
          for (const auto& pair : common) {
            if (std::find(chosen.begin(), chosen.end(), pair) != chosen.end()) kept.push_back(pair);
          }
          common.swap(kept);
        }
        return;
      }
      const int i = group[index];
      for (int j : candidates_of_left[i]) {
        bool ok = true;
        for (const auto& [k, l] : chosen) ok = ok && compatible(i, j, k, l);
        if (!ok) continue;
        chosen.emplace_back(i, j);
        search(index + 1, cost_so_far + cost[i][j]);
        chosen.pop_back();
      }
      search(index + 1, cost_so_far);  // leave i unmatched
    };
    search(0, 0.0);
    if (nodes <= kMaxSearchNodes) {
      common = best;
      second_pass = true;
      nodes = 0;
      search(0, 0.0);
    }
    if (nodes <= kMaxSearchNodes) {
      matches.insert(matches.end(), common.begin(), common.end());
      continue;
    }

    // Too large to search: accept a pair only if it is clearly the best of both its
    // detections' candidates.
    for (int i : group) {
      int best_j = -1;
      double c1 = std::numeric_limits<double>::infinity(), c2 = c1;
      for (int j : candidates_of_left[i]) {
        if (cost[i][j] < c1) {
          c2 = c1;
          c1 = cost[i][j];
          best_j = j;
        } else if (cost[i][j] < c2) {
          c2 = cost[i][j];
        }
      }
      if (best_j < 0 || c2 < c1 + options.ambiguity_margin) continue;
      bool unique = true;
      for (int k : group) {
        if (k != i && cost[k][best_j] < c1 + options.ambiguity_margin) unique = false;
      }
      if (unique) matches.emplace_back(i, best_j);
    }
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

}  // namespace auvdock
