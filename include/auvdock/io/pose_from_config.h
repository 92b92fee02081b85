// Reads a rigid transform from a configuration node: 16 numbers (row-major 4x4, last row
// 0 0 0 1) whose rotation block must be orthonormal with determinant +1 to 1e-6.
#pragma once

#include <string>

#include "auvdock/geometry/pose3.h"
#include "auvdock/io/yaml_config.h"

namespace auvdock {

Pose3 GetTransform(const ConfigNode& node, const std::string& key);
Pose3 GetTransform(const ConfigNode& node, const std::string& key, const Pose3& fallback);
// Same check for a row-major 4x4 given as 16 numbers; `fail` names the source on error.
bool TransformFromRowMajor(const std::vector<double>& values, Pose3* T, std::string* why);

}  // namespace auvdock
