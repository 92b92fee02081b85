#include "auvdock/io/yaml_writer.h"

#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "auvdock/io/csv.h"
#include "auvdock/io/input_error.h"

namespace auvdock {

void EmitNumber(YAML::Emitter& out, const std::string& key, double value) {
  out << YAML::Key << key << YAML::Value << FormatDouble(value);
}

void EmitNumbers(YAML::Emitter& out, const std::string& key, const std::vector<double>& values) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (double v : values) out << FormatDouble(v);
  out << YAML::EndSeq;
}

void EmitVector3(YAML::Emitter& out, const std::string& key, const Eigen::Vector3d& v) {
  EmitNumbers(out, key, {v.x(), v.y(), v.z()});
}

std::vector<double> TransformToRowMajor(const Pose3& T) {
  const Eigen::Matrix4d M = T.Matrix();
  std::vector<double> values;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) values.push_back(M(r, c));
  }
  return values;
}

void EmitTransform(YAML::Emitter& out, const std::string& key, const Pose3& T) {
  EmitNumbers(out, key, TransformToRowMajor(T));
}

void WriteYamlFile(const std::string& path, const std::string& comment,
                   const YAML::Emitter& out) {
  std::ofstream file(path);
  if (!file) throw InputError(path + ": cannot create file");
  std::istringstream lines(comment);
  std::string line;
  while (std::getline(lines, line)) file << "# " << line << '\n';
  file << out.c_str() << '\n';
  if (!file) throw InputError(path + ": write failed");
}

}  // namespace auvdock
