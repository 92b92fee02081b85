#include "auvdock/io/yaml_config.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "auvdock/io/input_error.h"

namespace auvdock {

// Keys read anywhere in the file, as full dotted paths, shared by all nodes of one file.
struct ConfigNode::Shared {
  std::string file;
  std::set<std::string> used;
  std::vector<std::pair<std::string, YAML::Node>> mappings;  // every mapping handed out
};

ConfigNode::ConfigNode(std::shared_ptr<Shared> shared, std::unique_ptr<YAML::Node> node,
                       std::string path)
    : shared_(std::move(shared)), node_(std::move(node)), file_(shared_->file),
      path_(std::move(path)) {
  shared_->mappings.emplace_back(path_, *node_);
}

ConfigNode::~ConfigNode() = default;
ConfigNode::ConfigNode(const ConfigNode& other)
    : shared_(other.shared_), node_(std::make_unique<YAML::Node>(*other.node_)),
      file_(other.file_), path_(other.path_) {}
ConfigNode& ConfigNode::operator=(const ConfigNode& other) {
  if (this != &other) {
    shared_ = other.shared_;
    node_ = std::make_unique<YAML::Node>(*other.node_);
    file_ = other.file_;
    path_ = other.path_;
  }
  return *this;
}

ConfigNode ConfigNode::LoadFile(const std::string& path) {
  // A folder opens as a stream on Linux and fails on the first read with an exception that is
  // not yaml-cpp's (found by fuzzing: a scenario's `dock: ..`).
  std::error_code error;  // a name too long for the file system: the open below says so
  if (std::filesystem::is_directory(path, error)) {
    throw InputError(path + ": is a folder, not a file");
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path + ": cannot open file");
  } catch (const YAML::Exception& e) {
    std::ostringstream os;
    os << path << ": line " << e.mark.line + 1 << ": malformed YAML: " << e.msg;
    throw InputError(os.str());
  }
  if (!root.IsMap()) throw InputError(path + ": expected a YAML mapping at the top level");
  auto shared = std::make_shared<Shared>();
  shared->file = path;
  return ConfigNode(shared, std::make_unique<YAML::Node>(root), "");
}

std::string ConfigNode::KeyPath(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

void ConfigNode::Fail(const std::string& key, const std::string& message) const {
  throw InputError(file_ + ": key '" + KeyPath(key) + "': " + message);
}

bool ConfigNode::Has(const std::string& key) const {
  const YAML::Node n = (*node_)[key];
  return n.IsDefined() && !n.IsNull();
}

YAML::Node ConfigNode::Lookup(const std::string& key) const {
  shared_->used.insert(KeyPath(key));
  const YAML::Node n = (*node_)[key];
  if (!n.IsDefined() || n.IsNull()) Fail(key, "missing");
  return n;
}

namespace {

bool ParseFiniteDouble(const YAML::Node& n, double* out) {
  if (!n.IsScalar()) return false;
  try {
    *out = n.as<double>();
  } catch (const YAML::Exception&) {
    return false;
  }
  return std::isfinite(*out);
}

std::string Describe(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  if (n.IsSequence()) return "a sequence";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

}  // namespace

double ConfigNode::GetDouble(const std::string& key) const {
  const YAML::Node n = Lookup(key);
  double v;
  if (!ParseFiniteDouble(n, &v)) Fail(key, "expected a finite number (got " + Describe(n) + ")");
  return v;
}

double ConfigNode::GetDouble(const std::string& key, double fallback) const {
  shared_->used.insert(KeyPath(key));
  return Has(key) ? GetDouble(key) : fallback;
}

double ConfigNode::GetPositive(const std::string& key) const {
  const double v = GetDouble(key);
  if (!(v > 0.0)) {
    std::ostringstream os;
    os << "must be positive (got " << v << ")";
    Fail(key, os.str());
  }
  return v;
}

double ConfigNode::GetPositive(const std::string& key, double fallback) const {
  shared_->used.insert(KeyPath(key));
  return Has(key) ? GetPositive(key) : fallback;
}

double ConfigNode::GetNonNegative(const std::string& key, double fallback) const {
  shared_->used.insert(KeyPath(key));
  if (!Has(key)) return fallback;
  const double v = GetDouble(key);
  if (v < 0.0) {
    std::ostringstream os;
    os << "must not be negative (got " << v << ")";
    Fail(key, os.str());
  }
  return v;
}

int ConfigNode::GetInt(const std::string& key) const {
  const YAML::Node n = Lookup(key);
  try {
    return n.as<int>();
  } catch (const YAML::Exception&) {
    Fail(key, "expected an integer (got " + Describe(n) + ")");
  }
}

int ConfigNode::GetInt(const std::string& key, int fallback) const {
  shared_->used.insert(KeyPath(key));
  return Has(key) ? GetInt(key) : fallback;
}

int64_t ConfigNode::GetInt64(const std::string& key, int64_t fallback) const {
  shared_->used.insert(KeyPath(key));
  if (!Has(key)) return fallback;
  const YAML::Node n = Lookup(key);
  try {
    return n.as<int64_t>();
  } catch (const YAML::Exception&) {
    Fail(key, "expected an integer (got " + Describe(n) + ")");
  }
}

bool ConfigNode::GetBool(const std::string& key, bool fallback) const {
  shared_->used.insert(KeyPath(key));
  if (!Has(key)) return fallback;
  const YAML::Node n = Lookup(key);
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    Fail(key, "expected true or false (got " + Describe(n) + ")");
  }
}

std::string ConfigNode::GetString(const std::string& key) const {
  const YAML::Node n = Lookup(key);
  if (!n.IsScalar()) Fail(key, "expected a string (got " + Describe(n) + ")");
  return n.Scalar();
}

std::string ConfigNode::GetString(const std::string& key, const std::string& fallback) const {
  shared_->used.insert(KeyPath(key));
  return Has(key) ? GetString(key) : fallback;
}

std::vector<double> ConfigNode::GetDoubles(const std::string& key) const {
  const YAML::Node n = Lookup(key);
  if (!n.IsSequence()) Fail(key, "expected a sequence of numbers (got " + Describe(n) + ")");
  std::vector<double> values;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v;
    if (!ParseFiniteDouble(n[i], &v)) {
      Fail(key, "element " + std::to_string(i) + " is not a finite number (got " +
                    Describe(n[i]) + ")");
    }
    values.push_back(v);
  }
  return values;
}

ConfigNode ConfigNode::Child(const std::string& key) const {
  const YAML::Node n = Lookup(key);
  if (!n.IsMap()) Fail(key, "expected a mapping (got " + Describe(n) + ")");
  return ConfigNode(shared_, std::make_unique<YAML::Node>(n), KeyPath(key));
}

ConfigNode ConfigNode::ChildOrEmpty(const std::string& key) const {
  shared_->used.insert(KeyPath(key));
  if (!Has(key)) {
    return ConfigNode(shared_, std::make_unique<YAML::Node>(YAML::NodeType::Map), KeyPath(key));
  }
  return Child(key);
}

std::vector<ConfigNode> ConfigNode::Children(const std::string& key) const {
  const YAML::Node n = Lookup(key);
  if (!n.IsSequence()) Fail(key, "expected a sequence (got " + Describe(n) + ")");
  std::vector<ConfigNode> children;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item_path = KeyPath(key) + "[" + std::to_string(i) + "]";
    if (!n[i].IsMap()) {
      throw InputError(file_ + ": key '" + item_path + "': expected a mapping");
    }
    children.push_back(ConfigNode(shared_, std::make_unique<YAML::Node>(n[i]), item_path));
  }
  return children;
}

void ConfigNode::CheckNoUnknownKeys() const {
  for (const auto& [path, mapping] : shared_->mappings) {
    if (!(path == path_ || path_.empty() || path.rfind(path_ + ".", 0) == 0 ||
          path.rfind(path_ + "[", 0) == 0)) {
      continue;
    }
    for (const auto& item : mapping) {
      const std::string key = item.first.Scalar();
      const std::string full = path.empty() ? key : path + "." + key;
      if (!shared_->used.count(full)) {
        throw InputError(file_ + ": key '" + full + "': unknown key");
      }
    }
  }
}

}  // namespace auvdock
