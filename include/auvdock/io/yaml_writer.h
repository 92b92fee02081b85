// Small helpers to emit auvdock's YAML files (calibration.yaml, dock.yaml) with numbers in
// their shortest round-trip form, so write -> read gives back the same doubles.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"

namespace YAML {
class Emitter;
}

namespace auvdock {

void EmitNumber(YAML::Emitter& out, const std::string& key, double value);
void EmitNumbers(YAML::Emitter& out, const std::string& key, const std::vector<double>& values);
void EmitVector3(YAML::Emitter& out, const std::string& key, const Eigen::Vector3d& v);
// A transform as 16 numbers, row-major 4x4 (the EuRoC T_BS convention).
void EmitTransform(YAML::Emitter& out, const std::string& key, const Pose3& T);
std::vector<double> TransformToRowMajor(const Pose3& T);
// Writes the emitter's text to path, with a leading comment block; throws InputError.
void WriteYamlFile(const std::string& path, const std::string& comment,
                   const YAML::Emitter& out);

}  // namespace auvdock
