#include "apps/dataset_input.h"

#include "auvdock/io/dock_io.h"
#include "auvdock/io/input_error.h"

namespace auvdock::cli {

void AddDockOption(CLI::App* sub, std::string* dock_file) {
  sub->add_option("--dock", *dock_file,
                  "dock.yaml: the dock's lights (default: the dataset's own dock.yaml; needed "
                  "for a EuRoC sequence without one)");
}

Dataset LoadDatasetWithDock(const std::string& dir, const std::string& dock_file,
                            std::vector<std::string>* skipped_rows) {
  Dataset dataset = LoadDataset(dir, skipped_rows);
  if (!dock_file.empty()) dataset.dock = LoadDockModel(dock_file);
  return dataset;
}

const DockModel& RequireDock(const Dataset& dataset) {
  if (!dataset.dock) {
    throw InputError(dataset.root +
                     ": no dock.yaml: the dock's lights are needed (give --dock FILE, or put a "
                     "dock.yaml in the dataset folder)");
  }
  return *dataset.dock;
}

}  // namespace auvdock::cli
