// summary.json of `auvdock run` / `auvdock smooth`: counts of frames, estimates, GO decisions,
// skipped measurements (with the log of what was skipped and every reset), and the time spent:
// data_duration_s and timing_s {decode (the work, on the decoding thread), decode_waited (the
// part of it the run waited for), frontend, backend, total (wall)}, plus the speed as a multiple
// of real time with and without decoding and for the back-end alone. In replay
// (--detections), given_identities {used, dropped, refused: {reason: images}}.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/vision_frame_source.h"
#include "auvdock/estimator/sliding_window_estimator.h"

namespace auvdock::cli {

struct RunCounters {
  int frames = 0;
  int go = 0;
  int rejections = 0;  // rows written to rejections.csv
  int symmetry_unresolved = 0;  // estimates known only up to the dock's symmetry
  double backend_s = 0.0;
  double total_s = 0.0;
  bool interrupted = false;
};

// The dataset's skipped rows on stderr ("auvdock: COMMAND: ..."), the first max_lines of them
// and then how many more: a stream that runs backwards skips every row until it is past its
// last time again, hundreds of lines that would bury the rest. summary.json's "log" has all.
void PrintSkippedRows(const char* command, const std::vector<std::string>& skipped_rows,
                      std::size_t max_lines = 10);

// One line on stdout when some estimates are known only up to the dock's symmetry.
void PrintSymmetryUnresolved(const char* command, int count);

// In replay, what became of the identities given with the detections (nothing when none were).
void PrintGivenIdentities(const VisionFrameSource& source);

// When the depth offset is not estimated (stats.depth_offset_m NaN) and the depth gate rejected
// more than a quarter of at least 20 samples: the depth disagrees with the other sensors, the
// sign of a sensor whose zero is not the dock survey's (on the default scenario with an offset
// of 0.3 m, 80-85 % of the samples are gated; without one, at most 1 %). The warning's text, or
// empty. MakeRunSummary puts it in "warnings"; PrintSensorDisagreements on stderr (with the
// DVL's and the fixes' below).
std::string DepthDisagreementWarning(const EstimatorStats& stats);
// The same for the DVL: its rate test, admission and gate refused more than half of at least 20
// samples (a DVL in another frame than its T_B_S says, rotated 180 deg about z say, or on
// another clock; with a heading sensor or lights the window sees that its velocity is not the
// vehicle's). Without a heading sensor and lights, a DVL turned 180 deg about z is the vehicle
// heading the other way to the acoustic start: nothing refuses it, the position holds and the
// heading is 180 deg off (simulated: 0.09 m, 3.09 rad); no warning can tell.
std::string DvlDisagreementWarning(const EstimatorStats& stats);
// The same for the acoustic fixes: the gate refused more than half of at least 10 (fixes in
// another frame than D, converted from a beacon that is not where the dock is, while the lights
// hold the state; without lights a divergence restarts from the fixes instead).
std::string UsblDisagreementWarning(const EstimatorStats& stats);
// The three warnings on stderr, when there are any.
void PrintSensorDisagreements(const char* command, const EstimatorStats& stats);

nlohmann::json MakeRunSummary(const VisionFrameSource& source, const EstimatorStats& stats,
                              const std::vector<std::string>& skipped_rows,
                              const RunCounters& counters);

}  // namespace auvdock::cli
