#include "auvdock/io/csv.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "auvdock/io/input_error.h"

namespace auvdock {

namespace {

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

}  // namespace

CsvReader::CsvReader(const std::string& path, std::vector<std::string> columns, bool allow_extra,
                     int optional_last)
    : path_(path), columns_(std::move(columns)), allow_extra_(allow_extra),
      optional_last_(optional_last), in_(path) {
  if (!in_) throw InputError(path + ": cannot open file");
}

void CsvReader::ExpectNamedHeaderRow() {
  const bool saved = allow_extra_;
  const int saved_optional = optional_last_;
  allow_extra_ = false;
  optional_last_ = 0;
  std::string expected;
  for (const auto& c : columns_) expected += (expected.empty() ? "" : ",") + c;
  if (!Next()) Fail("empty file: expected the header row '" + expected + "'");
  allow_extra_ = saved;
  optional_last_ = saved_optional;
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (fields_[i] != columns_[i]) {
      Fail("expected the header row '" + expected + "' (column " + std::to_string(i + 1) +
           " is '" + fields_[i] + "')");
    }
  }
}

bool CsvReader::Next() {
  std::string text;
  while (std::getline(in_, text)) {
    ++line_;
    text = Trim(text);
    if (text.empty() || text[0] == '#') continue;
    fields_.clear();
    std::stringstream ss(text);
    std::string field;
    while (std::getline(ss, field, ',')) fields_.push_back(Trim(field));
    if (!text.empty() && text.back() == ',') fields_.push_back("");
    const std::size_t required = columns_.size() - static_cast<std::size_t>(optional_last_);
    const bool count_ok = fields_.size() >= required &&
                          (allow_extra_ || fields_.size() <= columns_.size());
    if (!count_ok) {
      const std::string expected =
          optional_last_ == 0 ? std::to_string(columns_.size())
                              : std::to_string(required) + " to " + std::to_string(columns_.size());
      Fail("expected " + expected + " columns, found " + std::to_string(fields_.size()));
    }
    return true;
  }
  if (in_.bad()) Fail("read error");
  return false;
}

void CsvReader::Fail(const std::string& message) const {
  throw InputError(path_ + ": line " + std::to_string(line_) + ": " + message);
}

void CsvReader::FailColumn(int column, const std::string& message) const {
  Fail("column '" + columns_.at(column) + "': " + message);
}

int64_t CsvReader::Int64(int column) const {
  const std::string& f = fields_.at(column);
  int64_t value = 0;
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
  if (ec != std::errc() || end != f.data() + f.size()) {
    FailColumn(column, "not an integer ('" + f + "')");
  }
  return value;
}

double CsvReader::Double(int column) const {
  const std::string& f = fields_.at(column);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
  if (ec != std::errc() || end != f.data() + f.size() || !std::isfinite(value)) {
    FailColumn(column, "not a finite number ('" + f + "')");
  }
  return value;
}

bool CsvReader::HasNonFiniteNumber(int first, int last) const {
  for (int column = first; column <= last && column < static_cast<int>(fields_.size()); ++column) {
    const std::string& f = fields_[column];
    double value = 0.0;
    const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), value);
    if (ec == std::errc() && end == f.data() + f.size() && !std::isfinite(value)) return true;
  }
  return false;
}

std::string FormatDouble(double value) {
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return ec == std::errc() ? std::string(buffer, end) : std::string("nan");
}

CsvWriter::CsvWriter(const std::string& path, const std::string& header_line)
    : path_(path), out_(path) {
  if (!out_) throw InputError(path + ": cannot create file");
  out_ << header_line << '\n';
}

void CsvWriter::Row(int64_t t_ns, const std::vector<double>& values) {
  std::string line = std::to_string(t_ns);
  for (double v : values) {
    line += ',';
    line += FormatDouble(v);
  }
  Line(line);
}

void CsvWriter::Line(const std::string& line) {
  out_ << line << '\n';
  out_.flush();
  if (!out_) throw InputError(path_ + ": write failed");
}

void CsvWriter::Close() {
  if (out_.is_open()) out_.close();
}

void CheckIncreasingTime(const CsvReader& reader, int64_t previous_ns, int64_t t_ns) {
  if (t_ns <= previous_ns) {
    reader.Fail("timestamp " + std::to_string(t_ns) + " is not after the previous one (" +
                std::to_string(previous_ns) + ")");
  }
}

}  // namespace auvdock
