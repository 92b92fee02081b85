#include "auvdock/camera/pinhole_radtan_camera.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace auvdock {
namespace {

// The smallest r where the slope reaches 0: scanned in s up to r = 100 (a ray 89.4 deg off the
// axis), then bisected.
double FoldRadius(const std::array<double, 5>& d) {
  constexpr double kMaxS = 1e4;
  double lo = 0.0;
  for (double step = 1e-3; lo < kMaxS; step *= 1.05) {
    const double hi = std::min(kMaxS, lo + step);
    if (RadialDistortionSlope(d, hi) <= 0.0) {
      double a = lo, b = hi;
      for (int i = 0; i < 60; ++i) {
        const double m = 0.5 * (a + b);
        (RadialDistortionSlope(d, m) > 0.0 ? a : b) = m;
      }
      return std::sqrt(a);
    }
    lo = hi;
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace

PinholeRadtanCamera::PinholeRadtanCamera(int width, int height, double fx, double fy, double cx,
                                         double cy, const std::array<double, 5>& distortion)
    : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy),
      distortion_(distortion), fold_radius_(FoldRadius(distortion)) {
  assert(width > 0 && height > 0 && fx > 0 && fy > 0);
}

PinholeRadtanCamera PinholeRadtanCamera::FromHorizontalFov(
    int width, int height, double hfov_rad, const std::array<double, 5>& distortion) {
  const double f = 0.5 * width / std::tan(0.5 * hfov_rad);
  return PinholeRadtanCamera(width, height, f, f, 0.5 * (width - 1), 0.5 * (height - 1),
                             distortion);
}

Eigen::Matrix3d PinholeRadtanCamera::K() const {
  Eigen::Matrix3d K;
  K << fx_, 0.0, cx_, 0.0, fy_, cy_, 0.0, 0.0, 1.0;
  return K;
}

std::optional<Eigen::Vector2d> PinholeRadtanCamera::Project(const Eigen::Vector3d& p_C,
                                                            double min_depth) const {
  if (!(p_C.z() > min_depth)) return std::nullopt;
  const Eigen::Vector2d xy = p_C.head<2>() / p_C.z();
  if (!(xy.norm() < fold_radius_)) return std::nullopt;
  return ProjectNormalized(xy);
}

Eigen::Vector2d PinholeRadtanCamera::ProjectNormalized(const Eigen::Vector2d& xy) const {
  double xd, yd;
  DistortNormalized(distortion_, xy.x(), xy.y(), &xd, &yd);
  return Eigen::Vector2d(fx_ * xd + cx_, fy_ * yd + cy_);
}

Eigen::Vector2d PinholeRadtanCamera::Unproject(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d target((uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_);
  Eigen::Vector2d xy = target;  // distortion is mild: the distorted point is a good start
  for (int iteration = 0; iteration < 20; ++iteration) {
    // Residual and its 2x2 Jacobian by central differences (cheap, robust for any coefficient).
    double xd, yd;
    DistortNormalized(distortion_, xy.x(), xy.y(), &xd, &yd);
    const Eigen::Vector2d r(xd - target.x(), yd - target.y());
    if (r.squaredNorm() < 1e-26) break;
    Eigen::Matrix2d J;
    const double h = 1e-7;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d a = xy, b = xy;
      a[k] += h;
      b[k] -= h;
      double xa, ya, xb, yb;
      DistortNormalized(distortion_, a.x(), a.y(), &xa, &ya);
      DistortNormalized(distortion_, b.x(), b.y(), &xb, &yb);
      J.col(k) = Eigen::Vector2d(xa - xb, ya - yb) / (2.0 * h);
    }
    xy -= J.partialPivLu().solve(r);
  }
  return xy;
}

Eigen::Vector3d PinholeRadtanCamera::Bearing(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xy = Unproject(uv);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

bool PinholeRadtanCamera::InImage(const Eigen::Vector2d& uv, double margin) const {
  return uv.x() >= -0.5 + margin && uv.y() >= -0.5 + margin &&
         uv.x() <= width_ - 0.5 - margin && uv.y() <= height_ - 0.5 - margin;
}

}  // namespace auvdock
