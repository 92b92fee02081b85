// An output folder that appears all at once or not at all.
//
// The work is written into a sibling staging folder "<final>.partial-<pid>"; Commit() renames it
// to the final name (one rename on the same file system). If the object is destroyed without
// Commit() (an error, a cancellation), the staging folder is removed, so nothing half-written
// is left behind. The final folder must not exist, or must be an empty folder.
#pragma once

#include <string>

namespace auvdock {

class StagedDirectory {
 public:
  // Throws InputError if final_dir exists and is not an empty folder, or cannot be created.
  explicit StagedDirectory(const std::string& final_dir);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  // Where to write while the work runs.
  const std::string& staging_path() const { return staging_; }
  const std::string& final_path() const { return final_; }

  void Commit();

 private:
  std::string final_;
  std::string staging_;
  bool committed_ = false;
};

// Throws InputError unless path is absent or an empty folder.
void RequireAbsentOrEmptyDirectory(const std::string& path);

}  // namespace auvdock
