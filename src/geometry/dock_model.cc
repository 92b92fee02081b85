#include "auvdock/geometry/dock_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace auvdock {

bool DockModel::LightsCollinear(double tolerance_m) const {
  if (lights.size() < 3) return true;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& light : lights) centroid += light.p_D;
  centroid /= static_cast<double>(lights.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& light : lights) {
    const Eigen::Vector3d d = light.p_D - centroid;
    scatter += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  // The second-largest principal spread is the distance of the points from the best line.
  const double spread_off_line = std::sqrt(std::max(0.0, eig.eigenvalues()(1)) /
                                           static_cast<double>(lights.size()));
  return spread_off_line < tolerance_m;
}

const DockLight* DockModel::FindLight(int id) const {
  for (const auto& light : lights) {
    if (light.id == id) return &light;
  }
  return nullptr;
}

Eigen::Vector3d EarthRate_D(const DockModel& dock) {
  if (!dock.HasLatitude()) return Eigen::Vector3d::Zero();
  const double c = std::cos(dock.latitude_rad), s = std::sin(dock.latitude_rad);
  return kEarthRotationRate *
         Eigen::Vector3d(c * std::cos(dock.heading_rad), -c * std::sin(dock.heading_rad), -s);
}

}  // namespace auvdock
