// The rejected-measurement file written by `auvdock run` / `smooth` (rejections.csv): a header
// line, then one row per measurement the estimator left out (estimator/rejection.h)
//   timestamp_ns, sensor, statistic, reason
// in the order of rejection (`run`: frame by frame, flushed; `smooth`: in time order). The
// statistic is the chi-square value of a gated measurement, "nan" where there is none; the
// reason is one line without commas.
#pragma once

#include <string>
#include <vector>

#include "auvdock/estimator/rejection.h"

namespace auvdock {

std::string RejectionsCsvHeader();

// One row's text (without the newline); commas in the sensor or reason become semicolons.
std::string RejectionsCsvRow(const Rejection& rejection);

// Throws InputError naming the file and line on a malformed row.
std::vector<Rejection> ReadRejectionsCsv(const std::string& path);

}  // namespace auvdock
