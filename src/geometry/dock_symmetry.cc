#include "auvdock/geometry/dock_symmetry.h"

#include <cmath>
#include <sstream>
#include <string>

#include <Eigen/Geometry>

namespace auvdock {
namespace {

// Orthonormal right-handed frame of (u, v, u x v); false when u and v are (nearly) parallel.
bool Frame(const Eigen::Vector3d& u, const Eigen::Vector3d& v, Eigen::Matrix3d* F) {
  const Eigen::Vector3d e1 = u.normalized();
  const Eigen::Vector3d w = v - v.dot(e1) * e1;
  if (w.norm() < 1e-6 * std::max(1.0, v.norm())) return false;
  const Eigen::Vector3d e2 = w.normalized();
  F->col(0) = e1;
  F->col(1) = e2;
  F->col(2) = e1.cross(e2);
  return true;
}

}  // namespace

std::vector<DockSymmetry> FindDockSymmetries(const DockModel& dock, double tolerance_m) {
  const int n = static_cast<int>(dock.lights.size());
  DockSymmetry identity;
  for (int i = 0; i < n; ++i) identity.permutation.push_back(i);
  std::vector<DockSymmetry> out{identity};
  if (n < 3) return out;

  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const DockLight& l : dock.lights) c += l.p_D;
  c /= n;
  auto p = [&](int i) -> Eigen::Vector3d { return dock.lights[i].p_D - c; };
  int a = 0;
  for (int i = 1; i < n; ++i) {
    if (p(i).norm() > p(a).norm()) a = i;
  }
  int b = -1;
  double best = 0.0;
  for (int i = 0; i < n; ++i) {
    const double area = p(a).cross(p(i)).norm();
    if (area > best) {
      best = area;
      b = i;
    }
  }
  Eigen::Matrix3d F_ab;
  if (b < 0 || !Frame(p(a), p(b), &F_ab)) return out;
  // A planar layout: its normal, for leaving out the turns that show its other face.
  double off_plane = 0.0;
  for (int i = 0; i < n; ++i) off_plane = std::max(off_plane, std::abs(p(i).dot(F_ab.col(2))));
  const bool planar = off_plane <= tolerance_m;

  for (int i = 0; i < n; ++i) {
    if (std::abs(p(i).norm() - p(a).norm()) > tolerance_m) continue;
    for (int j = 0; j < n; ++j) {
      if (j == i || std::abs(p(j).norm() - p(b).norm()) > tolerance_m) continue;
      if (std::abs((p(i) - p(j)).norm() - (p(a) - p(b)).norm()) > tolerance_m) continue;
      Eigen::Matrix3d F_ij;
      if (!Frame(p(i), p(j), &F_ij)) continue;
      const Eigen::Matrix3d R = F_ij * F_ab.transpose();
      if (planar && (R * F_ab.col(2)).dot(F_ab.col(2)) < 0.0) continue;
      DockSymmetry s;
      s.R = R;
      s.t = c - R * c;
      std::vector<char> taken(n, 0);
      bool ok = true;
      for (int k = 0; k < n && ok; ++k) {
        const Eigen::Vector3d q = R * dock.lights[k].p_D + s.t;
        int match = -1;
        for (int m = 0; m < n; ++m) {
          if (!taken[m] && (dock.lights[m].p_D - q).norm() <= tolerance_m) {
            match = m;
            break;
          }
        }
        if (match < 0) ok = false;
        else {
          taken[match] = 1;
          s.permutation.push_back(match);
        }
      }
      if (!ok) continue;
      const Eigen::AngleAxisd aa(R);
      s.angle_rad = std::abs(aa.angle());
      if (s.IsIdentity()) continue;
      s.axis_D = aa.axis();
      out.push_back(s);
    }
  }
  return out;
}

std::vector<int> PermuteLabelling(const std::vector<int>& detection_of_light,
                                  const DockSymmetry& s) {
  std::vector<int> out(detection_of_light.size(), -1);
  for (size_t i = 0; i < detection_of_light.size(); ++i) {
    out[s.permutation[i]] = detection_of_light[i];
  }
  return out;
}

size_t CanonicalSymmetry(const std::vector<DockSymmetry>& symmetries,
                         const std::vector<int>& detection_of_light) {
  size_t best = 0;
  std::vector<int> smallest = detection_of_light;
  for (size_t k = 1; k < symmetries.size(); ++k) {
    std::vector<int> copy = PermuteLabelling(detection_of_light, symmetries[k]);
    if (copy < smallest) {
      smallest = std::move(copy);
      best = k;
    }
  }
  return best;
}

std::string DescribeDockSymmetries(const std::vector<DockSymmetry>& symmetries) {
  if (symmetries.size() <= 1) return "none";
  std::ostringstream s;
  s.precision(3);
  s << symmetries.size() << "-fold (";
  for (size_t k = 1; k < symmetries.size(); ++k) {
    const DockSymmetry& sym = symmetries[k];
    s << (k > 1 ? "; " : "") << std::lround(sym.angle_rad * 180.0 / 3.14159265358979323846)
      << " deg about (" << sym.axis_D.x() << " " << sym.axis_D.y() << " " << sym.axis_D.z() << ")";
  }
  s << ")";
  return s.str();
}

}  // namespace auvdock
