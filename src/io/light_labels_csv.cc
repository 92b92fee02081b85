#include "auvdock/io/light_labels_csv.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "auvdock/io/input_error.h"

namespace auvdock {

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < line.size() && line[i + 1] == '"') {
          fields.back() += '"';
          ++i;
        } else {
          quoted = false;
        }
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else if (c != '\r') {
      fields.back() += c;
    }
  }
  if (quoted) throw std::invalid_argument("unterminated quote");
  for (std::string& f : fields) {
    const size_t a = f.find_first_not_of(" \t");
    const size_t b = f.find_last_not_of(" \t");
    f = a == std::string::npos ? std::string() : f.substr(a, b - a + 1);
  }
  return fields;
}

LightLabels LoadLightLabels(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the labels file");
  std::string line;
  int line_number = 0;
  auto fail = [&](const std::string& message) {
    throw InputError(path + ": line " + std::to_string(line_number) + ": " + message);
  };
  auto split = [&](const std::string& text) {
    try {
      return SplitCsvLine(text);
    } catch (const std::invalid_argument& e) {
      fail(e.what());
    }
    return std::vector<std::string>{};
  };
  int col_file = -1, col_u = -1, col_v = -1, col_status = -1, col_quality = -1, col_range = -1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> header = split(line);
    for (size_t i = 0; i < header.size(); ++i) {
      const std::string& h = header[i];
      const int c = static_cast<int>(i);
      if (h == "frame_file") col_file = c;
      if (h == "u") col_u = c;
      if (h == "v") col_v = c;
      if (h == "status") col_status = c;
      if (h == "quality") col_quality = c;
      if (h == "range_m") col_range = c;
    }
    break;
  }
  if (col_file < 0 || col_u < 0 || col_v < 0) {
    fail("the first row must name the columns frame_file, u and v");
  }
  const int needed = std::max({col_file, col_u, col_v, col_status, col_quality, col_range}) + 1;
  LightLabels labels;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> f = split(line);
    if (static_cast<int>(f.size()) < needed) {
      fail(std::to_string(f.size()) + " fields, expected at least " + std::to_string(needed));
    }
    const std::string& file = f[col_file];
    if (file.empty()) fail("column 'frame_file' is empty");
    std::vector<LightLabel>& frame = labels[file];
    const std::string status = col_status >= 0 ? f[col_status] : "ok";
    if (status == "none" || (f[col_u].empty() && f[col_v].empty())) continue;
    LightLabel label;
    if (status == "ok" || status.empty()) {
      label.status = LabelStatus::kOk;
    } else if (status == "border") {
      label.status = LabelStatus::kBorder;
    } else if (status == "edge") {
      label.status = LabelStatus::kEdge;
    } else {
      fail("column 'status': '" + status + "' (ok, border, edge, none)");
    }
    auto number = [&](int col, const char* name) {
      size_t used = 0;
      double value = 0.0;
      try {
        value = std::stod(f[col], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != f[col].size() || !std::isfinite(value)) {
        fail(std::string("column '") + name + "': not a finite number ('" + f[col] + "')");
      }
      return value;
    };
    label.uv = Eigen::Vector2d(number(col_u, "u"), number(col_v, "v"));
    if (col_range >= 0 && !f[col_range].empty()) {
      label.range_m = number(col_range, "range_m");
      if (label.range_m < 0.0) fail("column 'range_m': negative");
    }
    label.good = col_quality < 0 || f[col_quality] == "good";
    frame.push_back(label);
  }
  if (labels.empty()) throw InputError(path + ": no labelled frame");
  return labels;
}

}  // namespace auvdock
