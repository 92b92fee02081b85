// Reading and writing the comma-separated sensor files of a dataset (EuRoC/ASL style).
//
// A file starts with one header line beginning with '#'; every other line is a row of
// comma-separated values, the first the timestamp in integer nanoseconds. Numbers are written
// in the shortest form that reads back to the same double (std::to_chars), so a write -> read
// round trip is bit-exact. Errors name the file, the line and the column:
//   "imu0/data.csv: line 17: column 'a_RS_S_x': not a finite number ('nan')"
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace auvdock {

class CsvReader {
 public:
  // Opens the file and reads the header. `columns` are the names used in error messages; a row
  // must have exactly columns.size() fields (or at least that many when allow_extra); the last
  // optional_last of them may be left out (size() says how many a row has).
  CsvReader(const std::string& path, std::vector<std::string> columns, bool allow_extra = false,
            int optional_last = 0);

  // For user files whose first row names the columns ("X,Y,Z,u,v"): reads that row and
  // throws unless it lists exactly the expected names.
  void ExpectNamedHeaderRow();

  // Reads the next non-empty row; false at the end of the file.
  bool Next();

  int64_t Int64(int column) const;
  double Double(int column) const;  // finite only
  // True when one of the columns [first, last] holds a number that parses as NaN or +-Inf
  // (malformed text is not reported here; Double() rejects it).
  bool HasNonFiniteNumber(int first, int last) const;
  const std::string& String(int column) const { return fields_.at(column); }
  int size() const { return static_cast<int>(fields_.size()); }
  int line() const { return line_; }
  const std::string& path() const { return path_; }

  // Throws InputError "path: line N: message".
  [[noreturn]] void Fail(const std::string& message) const;
  [[noreturn]] void FailColumn(int column, const std::string& message) const;

 private:
  std::string path_;
  std::vector<std::string> columns_;
  bool allow_extra_;
  int optional_last_;
  std::ifstream in_;
  std::vector<std::string> fields_;
  int line_ = 0;
};

// Formats a double in its shortest round-trip form ("0.1", "1e-05", "-3.25").
std::string FormatDouble(double value);

// A CSV file written row by row and flushed at every row, so an interrupted run keeps what it
// wrote.
class CsvWriter {
 public:
  CsvWriter() = default;
  CsvWriter(const std::string& path, const std::string& header_line);
  bool is_open() const { return out_.is_open(); }
  // Appends one row: t_ns followed by the values.
  void Row(int64_t t_ns, const std::vector<double>& values);
  // Appends a raw, already formatted line (without the newline).
  void Line(const std::string& line);
  void Close();

 private:
  std::string path_;
  std::ofstream out_;
};

// Verifies that timestamps are strictly increasing; throws InputError naming file and line.
void CheckIncreasingTime(const CsvReader& reader, int64_t previous_ns, int64_t t_ns);

}  // namespace auvdock
