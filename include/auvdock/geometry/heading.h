// Headings in the dock frame: what an AHRS or a compass measures (io/measurements.h,
// HeadingMeasurement), as a function of the body's attitude in D.
//
// The heading of a direction a (in D) is its angle about the downward vertical g_hat (the
// dock's gravity direction), clockwise seen from above, from the heading reference:
//   heading(a) = dock_heading + atan2(g_hat . (e x a), e . a)
// where e is the horizontal reference axis of D (D's x axis with its vertical part removed,
// normalised; D's z axis when x is vertical) and dock_heading the heading of e in the sensor's
// reference (dock.yaml heading_deg). Only a's horizontal part counts: its vertical part drops
// out of both terms. A sensor's heading is that of its x axis, a = R_D_B R_B_S e_x.
// Units: radians.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "auvdock/geometry/dock_model.h"

namespace auvdock {

struct HeadingReference {
  Eigen::Vector3d down_D = Eigen::Vector3d::UnitZ();       // g_hat
  Eigen::Vector3d reference_D = Eigen::Vector3d::UnitX();  // e
  double dock_heading_rad = 0.0;

  static HeadingReference OfDock(const DockModel& dock) {
    HeadingReference h;
    h.down_D = dock.gravity_D.normalized();
    const auto horizontal = [&](const Eigen::Vector3d& v) {
      return Eigen::Vector3d(v - h.down_D.dot(v) * h.down_D);
    };
    Eigen::Vector3d e = horizontal(Eigen::Vector3d::UnitX());
    if (e.norm() < 0.1) e = horizontal(Eigen::Vector3d::UnitZ());
    h.reference_D = e.normalized();
    h.dock_heading_rad = dock.heading_rad;
    return h;
  }

  // heading(a) (above); T is double or a ceres::Jet.
  template <typename T>
  T HeadingOf(const Eigen::Matrix<T, 3, 1>& a_D) const {
    const Eigen::Matrix<T, 3, 1> e = reference_D.cast<T>();
    using std::atan2;
    return T(dock_heading_rad) + atan2(down_D.cast<T>().dot(e.cross(a_D)), e.dot(a_D));
  }
};

// x wrapped to (-pi, pi]; T is double or a ceres::Jet.
template <typename T>
T WrapAngle(const T& x) {
  using std::atan2;
  using std::cos;
  using std::sin;
  return atan2(sin(x), cos(x));
}

}  // namespace auvdock
