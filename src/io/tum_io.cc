#include "auvdock/io/tum_io.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <system_error>
#include <vector>

#include "auvdock/io/input_error.h"

namespace auvdock {
namespace {

constexpr int kNumColumns = 8;
constexpr std::array<const char*, kNumColumns> kColumnNames = {"t",  "tx", "ty", "tz",
                                                               "qx", "qy", "qz", "qw"};
constexpr char kHeader[] = "# t[s] tx[m] ty[m] tz[m] qx qy qz qw  (T_D_B: body B in dock frame D)";
// Below this norm a quaternion's direction is noise: the row is refused, not normalized.
constexpr double kMinQuaternionNorm = 1e-9;

bool IsBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}
bool IsDigit(char c) { return c >= '0' && c <= '9'; }

std::vector<std::string> SplitOnBlanks(const std::string& line) {
  std::vector<std::string> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsBlank(line[i])) ++i;
    const size_t begin = i;
    while (i < line.size() && !IsBlank(line[i])) ++i;
    if (i > begin) tokens.push_back(line.substr(begin, i - begin));
  }
  return tokens;
}

// Locale-independent strict parse of a whole token as a double ("+1.5" allowed). Returns false
// if the token is not entirely a number or is out of the double range; NaN and Inf are parsed
// and left to the caller to refuse, so that the message can say so.
bool ParseDouble(const std::string& token, double* value) {
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') {
    ++first;
    if (first != last && *first == '-') return false;  // "+-1"
  }
  const std::from_chars_result result = std::from_chars(first, last, *value);
  return result.ec == std::errc() && result.ptr == last;
}

// Parses a run of at most 19 decimal digits (fits in uint64).
uint64_t DigitsToUint64(const std::string& digits) {
  assert(digits.size() <= 19);
  uint64_t v = 0;
  for (char c : digits) v = 10 * v + static_cast<uint64_t>(c - '0');
  return v;
}

std::string FormatDouble(double value) {
  std::array<char, 64> buffer;
  const std::to_chars_result result =
      std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  assert(result.ec == std::errc());
  return std::string(buffer.data(), result.ptr);
}

std::string FormatTumLine(const StampedPose& pose) {
  const Eigen::Quaterniond& q = pose.T_D_B.q;
  const Eigen::Vector3d& p = pose.T_D_B.p;
  std::string line = FormatNanosecondsAsSeconds(pose.t_ns);
  for (double v : {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()}) {
    line += ' ';
    line += FormatDouble(v);
  }
  line += '\n';
  return line;
}

std::string LinePrefix(const std::string& path, int line_number) {
  return path + ": line " + std::to_string(line_number) + ": ";
}

}  // namespace

bool ParseSecondsToNanoseconds(const std::string& text, int64_t* t_ns) {
  size_t i = 0;
  const size_t n = text.size();
  bool negative = false;
  if (i < n && (text[i] == '+' || text[i] == '-')) {
    negative = text[i] == '-';
    ++i;
  }
  // The number is digits * 10^(exponent - num_fraction_digits) seconds.
  std::string digits;
  int64_t num_fraction_digits = 0;
  bool any_digit = false;
  for (; i < n && IsDigit(text[i]); ++i) {
    digits.push_back(text[i]);
    any_digit = true;
  }
  if (i < n && text[i] == '.') {
    for (++i; i < n && IsDigit(text[i]); ++i) {
      digits.push_back(text[i]);
      ++num_fraction_digits;
      any_digit = true;
    }
  }
  if (!any_digit) return false;
  int64_t exponent = 0;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    bool exponent_negative = false;
    if (i < n && (text[i] == '+' || text[i] == '-')) {
      exponent_negative = text[i] == '-';
      ++i;
    }
    bool any_exponent_digit = false;
    // Saturate: beyond 1e9 the result is 0 or an overflow either way.
    for (; i < n && IsDigit(text[i]); ++i) {
      exponent = std::min<int64_t>(10 * exponent + (text[i] - '0'), 1000000000);
      any_exponent_digit = true;
    }
    if (!any_exponent_digit) return false;
    if (exponent_negative) exponent = -exponent;
  }
  if (i != n) return false;

  const size_t first_nonzero = digits.find_first_not_of('0');
  if (first_nonzero == std::string::npos) {
    *t_ns = 0;
    return true;
  }
  digits.erase(0, first_nonzero);
  const int64_t num_digits = static_cast<int64_t>(digits.size());

  // Nanoseconds = digits * 10^shift.
  const int64_t shift = exponent - num_fraction_digits + 9;
  uint64_t magnitude = 0;
  if (shift >= 0) {
    if (num_digits > 19) return false;  // >= 1e19 ns, beyond int64
    magnitude = DigitsToUint64(digits);
    for (int64_t k = 0; k < shift; ++k) {
      if (magnitude > std::numeric_limits<uint64_t>::max() / 10) return false;
      magnitude *= 10;
    }
  } else {
    const int64_t num_dropped = -shift;
    if (num_dropped <= num_digits) {
      const int64_t num_kept = num_digits - num_dropped;
      if (num_kept > 19) return false;
      magnitude = DigitsToUint64(digits.substr(0, num_kept));
      // Round half away from zero: the dropped part is >= 1/2 iff its first digit is >= 5.
      if (digits[num_kept] >= '5') ++magnitude;
    }  // else: below 0.1 ns, rounds to 0.
  }
  const uint64_t limit =
      static_cast<uint64_t>(std::numeric_limits<int64_t>::max()) + (negative ? 1u : 0u);
  if (magnitude > limit) return false;
  if (negative) {
    *t_ns =
        magnitude == limit ? std::numeric_limits<int64_t>::min() : -static_cast<int64_t>(magnitude);
  } else {
    *t_ns = static_cast<int64_t>(magnitude);
  }
  return true;
}

std::string FormatNanosecondsAsSeconds(int64_t t_ns) {
  // Through uint64 so that INT64_MIN has a magnitude.
  const uint64_t magnitude =
      t_ns < 0 ? uint64_t{0} - static_cast<uint64_t>(t_ns) : static_cast<uint64_t>(t_ns);
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%s%" PRIu64 ".%09" PRIu64, t_ns < 0 ? "-" : "",
                magnitude / 1000000000u, magnitude % 1000000000u);
  return buffer;
}

Trajectory ReadTumTrajectory(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(path + ": is a directory, expected a TUM trajectory file");
  }
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open trajectory file");

  Trajectory trajectory;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t first = line.find_first_not_of(" \t\r\n\v\f");
    if (first == std::string::npos || line[first] == '#') continue;

    const std::vector<std::string> tokens = SplitOnBlanks(line);
    if (tokens.size() != kNumColumns) {
      throw InputError(LinePrefix(path, line_number) + "expected " + std::to_string(kNumColumns) +
                       " columns (t tx ty tz qx qy qz qw), got " + std::to_string(tokens.size()));
    }
    StampedPose pose;
    if (!ParseSecondsToNanoseconds(tokens[0], &pose.t_ns)) {
      throw InputError(LinePrefix(path, line_number) + "timestamp '" + tokens[0] +
                       "' is not a decimal number of seconds within the int64 nanosecond range");
    }
    std::array<double, kNumColumns> values{};
    for (int c = 1; c < kNumColumns; ++c) {
      if (!ParseDouble(tokens[c], &values[c])) {
        throw InputError(LinePrefix(path, line_number) + "column " + std::to_string(c + 1) + " (" +
                         kColumnNames[c] + ") '" + tokens[c] + "' is not a number");
      }
      if (!std::isfinite(values[c])) {
        throw InputError(LinePrefix(path, line_number) + "column " + std::to_string(c + 1) + " (" +
                         kColumnNames[c] + ") is not finite (" + tokens[c] + ")");
      }
    }
    // TUM order is qx qy qz qw; Eigen's constructor takes w first.
    const Eigen::Quaterniond q(values[7], values[4], values[5], values[6]);
    if (!(q.norm() > kMinQuaternionNorm)) {
      throw InputError(LinePrefix(path, line_number) + "quaternion (" + tokens[4] + " " +
                       tokens[5] + " " + tokens[6] + " " + tokens[7] +
                       ") has (almost) zero norm and cannot be normalized");
    }
    if (!trajectory.empty() && pose.t_ns <= trajectory.back().t_ns) {
      throw InputError(LinePrefix(path, line_number) + "timestamp " +
                       FormatNanosecondsAsSeconds(pose.t_ns) +
                       " s is not after the previous one (" +
                       FormatNanosecondsAsSeconds(trajectory.back().t_ns) + " s)");
    }
    pose.T_D_B = Pose3(q, Eigen::Vector3d(values[1], values[2], values[3]));
    trajectory.push_back(pose);
  }
  if (in.bad()) throw InputError(path + ": read error after line " + std::to_string(line_number));
  return trajectory;
}

void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  std::ofstream out(path, std::ios::out | std::ios::trunc);
  if (!out) throw InputError(path + ": cannot open for writing");
  out << kHeader << '\n';
  for (size_t i = 0; i < trajectory.size(); ++i) {
    assert(i == 0 || trajectory[i].t_ns > trajectory[i - 1].t_ns);
    out << FormatTumLine(trajectory[i]);
  }
  out.close();
  if (!out) throw InputError(path + ": write failed");
}

TumWriter::TumWriter(const std::string& path) : path_(path) {
  out_.open(path, std::ios::out | std::ios::trunc);
  if (!out_) throw InputError(path + ": cannot open for writing");
  out_ << kHeader << '\n';
  out_.flush();
  if (!out_) throw InputError(path + ": write failed");
}

void TumWriter::Append(const StampedPose& pose) {
  assert(!last_t_ns_ || pose.t_ns > *last_t_ns_);
  out_ << FormatTumLine(pose);
  out_.flush();
  if (!out_) throw InputError(path_ + ": write failed");
  last_t_ns_ = pose.t_ns;
  ++num_poses_;
}

}  // namespace auvdock
