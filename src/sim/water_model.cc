#include "auvdock/sim/water_model.h"

#include <algorithm>
#include <cmath>

namespace auvdock {

const char* WaterTypeName(WaterType type) {
  switch (type) {
    case WaterType::kClear:
      return "clear";
    case WaterType::kCoastal:
      return "coastal";
    case WaterType::kTurbid:
      return "turbid";
  }
  return "clear";
}

bool ParseWaterType(const std::string& text, WaterType* type) {
  for (WaterType candidate : {WaterType::kClear, WaterType::kCoastal, WaterType::kTurbid}) {
    if (text == WaterTypeName(candidate)) {
      *type = candidate;
      return true;
    }
  }
  return false;
}

WaterModel WaterModel::ForType(WaterType type) {
  // Values and their reasoning: see the header.
  WaterModel water;
  switch (type) {
    case WaterType::kClear:
      water.attenuation_per_m = Eigen::Vector3d(0.06, 0.09, 0.30);
      water.veiling_light = Eigen::Vector3d(0.42, 0.22, 0.03);
      break;
    case WaterType::kCoastal:
      water.attenuation_per_m = Eigen::Vector3d(0.45, 0.32, 0.55);
      water.veiling_light = Eigen::Vector3d(0.32, 0.38, 0.10);
      break;
    case WaterType::kTurbid:
      water.attenuation_per_m = Eigen::Vector3d(1.10, 0.75, 1.05);
      water.veiling_light = Eigen::Vector3d(0.30, 0.42, 0.24);
      break;
  }
  return water;
}

Eigen::Vector3d WaterModel::Transmission(double range_m) const {
  const double r = std::max(0.0, range_m);
  return (-attenuation_per_m * r).array().exp().matrix();
}

}  // namespace auvdock
