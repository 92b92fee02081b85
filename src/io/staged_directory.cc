#include "auvdock/io/staged_directory.h"

#include <unistd.h>

#include <filesystem>

#include "auvdock/io/input_error.h"

namespace fs = std::filesystem;

namespace auvdock {

void RequireAbsentOrEmptyDirectory(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) return;
  if (!fs::is_directory(status)) throw InputError(path + ": exists and is not a folder");
  if (!fs::is_empty(path, ec)) throw InputError(path + ": output folder exists and is not empty");
}

StagedDirectory::StagedDirectory(const std::string& final_dir) {
  fs::path final_path = fs::path(final_dir).lexically_normal();
  if (final_path.filename().empty()) final_path = final_path.parent_path();
  final_ = final_path.string();
  RequireAbsentOrEmptyDirectory(final_);
  staging_ = final_ + ".partial-" + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(staging_, ec);
  if (!fs::create_directories(staging_, ec) || ec) {
    throw InputError(final_ + ": cannot create output folder (" + ec.message() + ")");
  }
}

StagedDirectory::~StagedDirectory() {
  if (!committed_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void StagedDirectory::Commit() {
  std::error_code ec;
  RequireAbsentOrEmptyDirectory(final_);  // someone may have written there meanwhile
  fs::remove(final_, ec);                 // an empty folder may be replaced
  fs::rename(staging_, final_, ec);
  if (ec) throw InputError(final_ + ": cannot move output into place (" + ec.message() + ")");
  committed_ = true;
}

}  // namespace auvdock
