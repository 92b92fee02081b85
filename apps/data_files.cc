#include "apps/data_files.h"

namespace auvdock::cli {

std::filesystem::path ExecutableDir() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

std::filesystem::path DataDir() {
  const std::filesystem::path bin = ExecutableDir();
  if (bin.empty()) return {};
  const std::filesystem::path share = bin.parent_path() / "share" / "auvdock";
  std::error_code error;
  if (!std::filesystem::is_directory(share, error)) return {};
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(share, error);
  return error ? share : canonical;
}

std::string DataPath(const std::string& relative) {
  const std::filesystem::path dir = DataDir();
  return dir.empty() ? "data/" + relative : (dir / relative).string();
}

}  // namespace auvdock::cli
