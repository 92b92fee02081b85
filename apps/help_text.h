// The footers of the subcommands' --help: what each needs, which files it writes, an example,
// and the shipped files it can use, with their paths as this binary finds them (data_files.h).
#pragma once

#include <string>

namespace auvdock::cli {

std::string SimulateHelp();
std::string RunHelp();     // run
std::string SmoothHelp();  // smooth
std::string CrlbHelp();
std::string FrontendHelp();
std::string EvaluateHelp();
std::string PnpHelp();
std::string DetectHelp();
std::string DemoHelp();

}  // namespace auvdock::cli
