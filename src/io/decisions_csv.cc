#include "auvdock/io/decisions_csv.h"

#include <algorithm>

#include "auvdock/io/csv.h"

namespace auvdock {

std::string DecisionsCsvHeader() { return "#timestamp [ns],decision,reason"; }

std::string DecisionsCsvRow(const StampedDecision& decision) {
  std::string reason = decision.reason;
  std::replace(reason.begin(), reason.end(), ',', ';');
  std::replace(reason.begin(), reason.end(), '\n', ' ');
  return std::to_string(decision.t_ns) + "," + (decision.go ? "GO" : "NO-GO") + "," + reason;
}

std::vector<StampedDecision> ReadDecisionsCsv(const std::string& path) {
  CsvReader reader(path, {"timestamp", "decision", "reason"});
  std::vector<StampedDecision> rows;
  while (reader.Next()) {
    StampedDecision row;
    row.t_ns = reader.Int64(0);
    CheckIncreasingTime(reader, rows.empty() ? INT64_MIN : rows.back().t_ns, row.t_ns);
    const std::string& decision = reader.String(1);
    if (decision != "GO" && decision != "NO-GO") {
      reader.FailColumn(1, "expected GO or NO-GO (got '" + decision + "')");
    }
    row.go = decision == "GO";
    row.reason = reader.String(2);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace auvdock
