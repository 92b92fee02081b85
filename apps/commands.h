// Subcommands of the auvdock command line. Each Add*Command() registers its options on the
// root CLI11 app; its callback runs the command and throws auvdock::InputError on bad input
// (the caller prints one line and exits 2). A command returns normally on success.
#pragma once

#include <CLI/CLI.hpp>

namespace auvdock::cli {

void AddSimulateCommand(CLI::App& root);
void AddEvaluateCommand(CLI::App& root);
void AddPnpCommand(CLI::App& root);
void AddFrontendCommand(CLI::App& root);
void AddRunCommand(CLI::App& root);
void AddSmoothCommand(CLI::App& root);
void AddCrlbCommand(CLI::App& root);
void AddDetectCommand(CLI::App& root);
void AddDemoCommand(CLI::App& root);

}  // namespace auvdock::cli
