// The dataset a subcommand reads and the dock it is given: `--dataset DIR [--dock FILE]`.
// A dataset folder of ours holds its dock.yaml; a real EuRoC sequence has none (a dock.yaml beside
// its mav0/ is read, auvdock/io/dataset.h). --dock gives the dock's light layout from any file,
// and wins over the folder's own.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "auvdock/io/dataset.h"

namespace auvdock::cli {

// Registers --dock on a subcommand.
void AddDockOption(CLI::App* sub, std::string* dock_file);

// LoadDataset(dir, skipped_rows), its dock replaced by dock_file's when that is not empty.
// Throws InputError (naming the file) on a malformed or missing dock file.
Dataset LoadDatasetWithDock(const std::string& dir, const std::string& dock_file,
                            std::vector<std::string>* skipped_rows = nullptr);

// The dataset's dock; InputError naming the folder and both ways to give one when it has none.
const DockModel& RequireDock(const Dataset& dataset);

}  // namespace auvdock::cli
