// Strict reading of YAML configuration files (scenario, calibration, dock).
//
// A ConfigNode wraps one YAML mapping and remembers its dotted key path ("imu.rate_hz") and the
// file it came from. Every read marks the key as used; CheckNoUnknownKeys() then rejects any key
// that was never read, so a typo ("tilt_dgr") is an error instead of a silently ignored default.
// All errors are InputError with one line naming the file and the key:
//   "data/scenarios/default.yaml: key 'imu.rate_hz': must be positive (got 0)"
#pragma once

#include <array>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace YAML {
class Node;
}

namespace auvdock {

class ConfigNode {
 public:
  // Parses a YAML file whose root must be a mapping.
  static ConfigNode LoadFile(const std::string& path);
  ~ConfigNode();
  ConfigNode(const ConfigNode&);
  ConfigNode& operator=(const ConfigNode&);

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

  bool Has(const std::string& key) const;

  double GetDouble(const std::string& key) const;
  double GetDouble(const std::string& key, double fallback) const;
  // A double that must be > 0.
  double GetPositive(const std::string& key) const;
  double GetPositive(const std::string& key, double fallback) const;
  double GetNonNegative(const std::string& key, double fallback) const;
  int GetInt(const std::string& key) const;
  int GetInt(const std::string& key, int fallback) const;
  int64_t GetInt64(const std::string& key, int64_t fallback) const;
  bool GetBool(const std::string& key, bool fallback) const;
  std::string GetString(const std::string& key) const;
  std::string GetString(const std::string& key, const std::string& fallback) const;
  std::vector<double> GetDoubles(const std::string& key) const;  // a sequence of numbers
  // A sequence of exactly N numbers.
  template <int N>
  Eigen::Matrix<double, N, 1> GetVector(const std::string& key) const {
    const std::vector<double> v = GetDoubles(key);
    if (static_cast<int>(v.size()) != N) Fail(key, "expected " + std::to_string(N) + " numbers");
    return Eigen::Map<const Eigen::Matrix<double, N, 1>>(v.data());
  }
  template <int N>
  Eigen::Matrix<double, N, 1> GetVector(const std::string& key,
                                        const Eigen::Matrix<double, N, 1>& fallback) const {
    return Has(key) ? GetVector<N>(key) : fallback;
  }

  ConfigNode Child(const std::string& key) const;  // a required mapping
  // An optional mapping: returns an empty mapping with the right path when absent.
  ConfigNode ChildOrEmpty(const std::string& key) const;
  std::vector<ConfigNode> Children(const std::string& key) const;  // a sequence of mappings

  // Throws for the first key of this mapping (and of every child read through it) that was
  // never read.
  void CheckNoUnknownKeys() const;

  // Throws InputError "file: key 'path.key': message".
  [[noreturn]] void Fail(const std::string& key, const std::string& message) const;

 private:
  struct Shared;
  ConfigNode(std::shared_ptr<Shared> shared, std::unique_ptr<YAML::Node> node, std::string path);
  std::string KeyPath(const std::string& key) const;
  YAML::Node Lookup(const std::string& key) const;  // marks used; throws if missing

  std::shared_ptr<Shared> shared_;
  std::unique_ptr<YAML::Node> node_;
  std::string file_;
  std::string path_;
};

}  // namespace auvdock
