#include "auvdock/io/rejections_csv.h"

#include <algorithm>
#include <cmath>

#include "auvdock/io/csv.h"

namespace auvdock {
namespace {

std::string OneField(std::string text) {
  std::replace(text.begin(), text.end(), ',', ';');
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

}  // namespace

std::string RejectionsCsvHeader() { return "#timestamp [ns],sensor,statistic,reason"; }

std::string RejectionsCsvRow(const Rejection& rejection) {
  return std::to_string(rejection.t_ns) + "," + OneField(rejection.sensor) + "," +
         (std::isfinite(rejection.statistic) ? FormatDouble(rejection.statistic) : "nan") + "," +
         OneField(rejection.reason);
}

std::vector<Rejection> ReadRejectionsCsv(const std::string& path) {
  CsvReader reader(path, {"timestamp", "sensor", "statistic", "reason"});
  std::vector<Rejection> rows;
  while (reader.Next()) {
    Rejection row;
    row.t_ns = reader.Int64(0);
    row.sensor = reader.String(1);
    if (row.sensor.empty()) reader.FailColumn(1, "empty sensor name");
    row.statistic = reader.String(2) == "nan" ? kNoStatistic : reader.Double(2);
    row.reason = reader.String(3);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace auvdock
