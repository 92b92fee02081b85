// The go/no-go decision file written by `auvdock run` / `smooth` (decisions.csv) and read by
// `auvdock evaluate --decisions`: a header line, then one row per frame
//   timestamp_ns, GO | NO-GO, reason
// where the reason is one line without commas (GoNoGoDecision).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace auvdock {

struct StampedDecision {
  int64_t t_ns = 0;
  bool go = false;
  std::string reason;
};

std::string DecisionsCsvHeader();

// One row's text (without the newline); the reason's commas, if any, become semicolons.
std::string DecisionsCsvRow(const StampedDecision& decision);

// Throws InputError naming the file and line on a malformed row, a decision other than GO or
// NO-GO, or a timestamp that does not increase.
std::vector<StampedDecision> ReadDecisionsCsv(const std::string& path);

}  // namespace auvdock
