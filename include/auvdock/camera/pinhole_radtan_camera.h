// Pinhole camera with radial-tangential (Brown-Conrady, OpenCV "plumb bob") distortion.
//
// Frames: camera frame C follows OpenCV: x right, y down, z along the optical axis.
// Projection of p_C = (X, Y, Z), Z > 0:
//   x = X/Z, y = Y/Z, r^2 = x^2 + y^2
//   radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
//   x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
//   u = fx x_d + cx,  v = fy y_d + cy           (pixels; (0,0) is the centre of the top-left pixel)
// Coefficients are in OpenCV's order (k1, k2, p1, p2, k3); EuRoC files give the first four.
// The model holds out to the fold radius r_fold, the smallest r > 0 where the radial mapping
// r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6) stops growing (d/dr = 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6
// = 0; +infinity when it never does): beyond it the polynomial sends farther rays back towards
// the image centre (a strongly barrel-distorted lens's k1 = -0.3 folds at ~50 deg off axis, and
// a light 60 deg off axis would land mid-image), where no lens images them. Project() refuses
// such points; calibrations are fitted inside the image, so r_fold lies beyond its corners.
// The templated DistortNormalized() is shared with the Ceres residuals of later issues.
#pragma once

#include <array>
#include <limits>
#include <optional>

#include <Eigen/Core>

namespace auvdock {

template <typename T>
void DistortNormalized(const std::array<double, 5>& d, const T& x, const T& y, T* x_d, T* y_d) {
  const T r2 = x * x + y * y;
  const T radial = T(1.0) + r2 * (T(d[0]) + r2 * (T(d[1]) + r2 * T(d[4])));
  const T xy2 = T(2.0) * x * y;
  *x_d = x * radial + T(d[2]) * xy2 + T(d[3]) * (r2 + T(2.0) * x * x);
  *y_d = y * radial + T(d[2]) * (r2 + T(2.0) * y * y) + T(d[3]) * xy2;
}

// d r_d / d r of the radial mapping r_d = r (1 + k1 r^2 + k2 r^4 + k3 r^6), as a function of
// r2 = r^2: 1 + 3 k1 r^2 + 5 k2 r^4 + 7 k3 r^6 (its first zero is the fold radius, above).
inline double RadialDistortionSlope(const std::array<double, 5>& d, double r2) {
  return 1.0 + r2 * (3.0 * d[0] + r2 * (5.0 * d[1] + r2 * 7.0 * d[4]));
}

class PinholeRadtanCamera {
 public:
  PinholeRadtanCamera() = default;
  // distortion: k1, k2, p1, p2, k3 (k3 may be 0).
  PinholeRadtanCamera(int width, int height, double fx, double fy, double cx, double cy,
                      const std::array<double, 5>& distortion);

  // A camera with the given horizontal field of view, principal point at the image centre.
  static PinholeRadtanCamera FromHorizontalFov(int width, int height, double hfov_rad,
                                               const std::array<double, 5>& distortion);

  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  const std::array<double, 5>& distortion() const { return distortion_; }
  Eigen::Matrix3d K() const;

  // Pixel of a point in front of the camera; nullopt if Z <= min_depth or the point lies beyond
  // the fold radius (above).
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_C, double min_depth = 1e-6) const;
  // Normalized (undistorted) image coordinates -> pixel.
  Eigen::Vector2d ProjectNormalized(const Eigen::Vector2d& xy) const;
  // Pixel -> undistorted normalized coordinates (x, y), by Gauss-Newton on the distortion.
  Eigen::Vector2d Unproject(const Eigen::Vector2d& uv) const;
  // Pixel -> unit bearing vector in C.
  Eigen::Vector3d Bearing(const Eigen::Vector2d& uv) const;

  // r_fold of the header (normalized units; +infinity when the distortion never folds).
  double fold_radius() const { return fold_radius_; }

  // True when the pixel lies inside the image with the given margin (pixels).
  bool InImage(const Eigen::Vector2d& uv, double margin = 0.0) const;

 private:
  int width_ = 0;
  int height_ = 0;
  double fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;
  std::array<double, 5> distortion_{};
  double fold_radius_ = std::numeric_limits<double>::infinity();
};

}  // namespace auvdock
