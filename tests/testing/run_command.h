// Runs the auvdock CLI as a child process and captures its exit status, stdout and stderr.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace auvdock::test {

struct CommandResult {
  int exit_status = -1;
  std::string out;
  std::string err;
};

// Runs build/bin/auvdock with the arguments (no shell involved).
CommandResult RunAuvdock(const std::vector<std::string>& args);

// Starts build/bin/auvdock, sends `signal` after `delay_s`, waits; returns the exit status.
CommandResult RunAuvdockAndSignal(const std::vector<std::string>& args, double delay_s, int signal);

// Starts build/bin/auvdock and sends `signal` as soon as ready() holds (polled every 2 ms; not
// sent if the command ends first or timeout_s passes), waits; returns the exit status.
CommandResult RunAuvdockAndSignalWhen(const std::vector<std::string>& args,
                                      const std::function<bool()>& ready, int signal,
                                      double timeout_s = 60.0);

// `simulate --detections-only` of the default approach on the T-shaped dock for duration_s,
// with extra_scenario's keys appended to the scenario (e.g. a heading sensor): the scenario in
// folder/name.yaml, the dataset in folder/name, whose path it returns. Throws std::runtime_error
// with the command's stderr when the simulation fails.
std::string SimulateDetections(const std::string& folder, const std::string& name,
                               double duration_s, const std::string& extra_scenario = "");

}  // namespace auvdock::test
