// Runs this auvdock binary again as a child process (the demo's steps are the subcommands
// themselves): its standard output into a string, its standard error into a log file. No shell.
#pragma once

#include <string>
#include <vector>

namespace auvdock::cli {

struct ChildResult {
  int exit_status = -1;  // the child's exit status; 128 + signal when a signal ended it
  std::string out;       // what it printed on stdout
  double wall_s = 0.0;
};

// /proc/self/exe ARGS..., stderr appended to log_path. InputError when it cannot be started.
ChildResult RunSelf(const std::vector<std::string>& args, const std::string& log_path);

// The last non-empty line of a text file ("" when none): a failed step's own one-line reason.
std::string LastLineOf(const std::string& path);

}  // namespace auvdock::cli
