// The plots of `auvdock evaluate --plots DIR`: scripts/plot_run.py (matplotlib), run with
// Debian's /usr/bin/python3 (where python3-matplotlib installs), found
//   1. at $AUVDOCK_PLOT_SCRIPT, when set;
//   2. beside the auvdock binary (the build copies it there: build/bin/plot_run.py);
//   3. in ../share/auvdock/ of the binary's folder (where `cmake --install` puts it).
// The script writes its PNGs to a temporary folder and moves them in only when all succeed.
#pragma once

#include <string>
#include <vector>

namespace auvdock::cli {

// The script's path; InputError naming the places looked in when there is none.
std::string FindPlotScript();

// Runs /usr/bin/python3 SCRIPT ARGS... (no shell); its stdout passes through. When it fails, an
// InputError with the last line it wrote to stderr (its own one-line reason), or its exit status.
void RunPlotScript(const std::string& script, const std::vector<std::string>& args);

}  // namespace auvdock::cli
