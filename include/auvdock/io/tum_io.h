// Reading and writing trajectories in the TUM RGB-D format (Sturm et al., "A benchmark for the
// evaluation of RGB-D SLAM systems", IROS 2012), the format evo and most SLAM evaluations read.
//
// One pose per line, whitespace separated:
//   t tx ty tz qx qy qz qw
// t is the timestamp in seconds (a decimal number), (tx ty tz) the position p_D_B in metres and
// (qx qy qz qw) the unit quaternion q_D_B -- the pose T_D_B of the body B in the dock frame D.
// Note the TUM quaternion order is x y z w (as in Eigen's memory, not Eigen's constructor).
//
// Time: inside auvdock time is int64 nanoseconds. The reader parses the decimal timestamp
// exactly (integer arithmetic on the digits, never through a double), so
// "1700000000.123456789" becomes 1700000000123456789 ns; digits beyond the nanosecond are
// rounded half away from zero. An exponent ("1.7e9") is accepted. The writer prints exactly
// 9 decimals of seconds from the integer nanoseconds, so write -> read is the identity on t_ns.
//
// Values are written with the shortest decimal that reads back to the same double
// (std::to_chars), i.e. at least as precise as 17 significant digits and usually shorter, so
// write -> read reproduces positions and quaternions to the last bit (up to the normalization
// of the quaternion on reading, ~1e-16).
//
// Reader validation: blank lines and lines whose first non-blank character is '#' are skipped;
// every other line must have exactly 8 finite numbers, a quaternion that can be normalized
// (norm > 1e-9; it is then normalized) and a timestamp strictly after the previous one.
// Anything else throws InputError("<path>: line N: <what>").
#pragma once

#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

#include "auvdock/geometry/stamped_pose.h"

namespace auvdock {

// Reads a whole TUM file. Throws InputError naming the file (and the line) on a missing or
// unreadable file or on a malformed line. An empty file (or only comments) gives an empty
// trajectory.
Trajectory ReadTumTrajectory(const std::string& path);

// Writes a whole trajectory (overwriting `path`), with a one-line '#' header. Throws InputError
// if the file cannot be written. Timestamps should be strictly increasing or the file will not
// read back.
void WriteTumTrajectory(const std::string& path, const Trajectory& trajectory);

// Streams poses to a TUM file as they are produced (e.g. by a running estimator): each
// Append() writes one line and flushes, so a crash or interrupt leaves a readable file with
// every pose appended so far.
class TumWriter {
 public:
  // Creates (truncates) `path` and writes the header line. Throws InputError if it cannot.
  explicit TumWriter(const std::string& path);

  TumWriter(const TumWriter&) = delete;
  TumWriter& operator=(const TumWriter&) = delete;

  // Appends one pose and flushes. Throws InputError if the write fails (e.g. disk full).
  // Timestamps must be strictly increasing (asserted).
  void Append(const StampedPose& pose);

  const std::string& path() const { return path_; }
  int64_t num_poses() const { return num_poses_; }

 private:
  std::string path_;
  std::ofstream out_;
  int64_t num_poses_ = 0;
  std::optional<int64_t> last_t_ns_;
};

// Parses a decimal number of seconds ("12", "-0.5", "1700000000.123456789", "1.7e9") to
// nanoseconds exactly, rounding below the nanosecond half away from zero. Returns false on
// anything that is not such a number or that overflows int64 nanoseconds.
bool ParseSecondsToNanoseconds(const std::string& text, int64_t* t_ns);

// Formats nanoseconds as seconds with exactly 9 decimals: 1500000001 -> "1.500000001".
std::string FormatNanosecondsAsSeconds(int64_t t_ns);

}  // namespace auvdock
