// Where the auvdock binary finds the files it ships: the scenarios, dock layouts and estimator
// options of data/, and the plot script. Installed (`cmake --install`), they are in
// PREFIX/share/auvdock beside PREFIX/bin/auvdock; in a build tree, the configure step makes
// build/share/auvdock a link to the source tree's data/ so that the same rule finds them:
//   DataDir() = (the binary's folder)/../share/auvdock, when it exists.
// The help texts print these paths, so a user sees where the built-in scenarios are.
#pragma once

#include <filesystem>
#include <string>

namespace auvdock::cli {

// The folder of the running binary (/proc/self/exe); empty if unknown.
std::filesystem::path ExecutableDir();

// The shipped data folder, or empty when neither an install nor a build tree holds one.
std::filesystem::path DataDir();

// DataDir() / relative as a string, or "data/" + relative (the source tree's) when there is none.
std::string DataPath(const std::string& relative);

}  // namespace auvdock::cli
