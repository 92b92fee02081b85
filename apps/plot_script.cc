#include "apps/plot_script.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/data_files.h"
#include "auvdock/io/input_error.h"

namespace auvdock::cli {
namespace {

constexpr const char* kPython = "/usr/bin/python3";
constexpr const char* kScriptName = "plot_run.py";

std::string LastLine(const std::string& text) {
  std::string trimmed = text;
  while (!trimmed.empty() && (trimmed.back() == '\n' || trimmed.back() == '\r')) trimmed.pop_back();
  const size_t newline = trimmed.rfind('\n');
  return newline == std::string::npos ? trimmed : trimmed.substr(newline + 1);
}

}  // namespace

std::string FindPlotScript() {
  if (const char* given = std::getenv("AUVDOCK_PLOT_SCRIPT"); given && *given) {
    if (!std::filesystem::is_regular_file(given)) {
      throw InputError(std::string("AUVDOCK_PLOT_SCRIPT: ") + given + ": no such file");
    }
    return given;
  }
  const std::filesystem::path dir = ExecutableDir();
  const std::vector<std::filesystem::path> candidates = {
      dir / kScriptName, dir.parent_path() / "share" / "auvdock" / kScriptName};
  for (const auto& candidate : candidates) {
    if (std::filesystem::is_regular_file(candidate)) return candidate.string();
  }
  throw InputError(std::string("--plots: ") + kScriptName + " not found (looked in " +
                   candidates[0].string() + " and " + candidates[1].string() +
                   "; set AUVDOCK_PLOT_SCRIPT)");
}

void RunPlotScript(const std::string& script, const std::vector<std::string>& args) {
  if (access(kPython, X_OK) != 0) {
    throw InputError(std::string("--plots needs ") + kPython +
                     " with python3-matplotlib (apt-get install python3-matplotlib)");
  }
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) throw InputError(std::string("--plots: pipe: ") + std::strerror(errno));
  std::vector<std::string> argv_strings = {kPython, script};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = fork();
  if (child < 0) {
    close(pipe_fds[0]);
    close(pipe_fds[1]);
    throw InputError(std::string("--plots: fork: ") + std::strerror(errno));
  }
  if (child == 0) {
    close(pipe_fds[0]);
    dup2(pipe_fds[1], STDERR_FILENO);
    close(pipe_fds[1]);
    execv(kPython, argv.data());
    _exit(127);
  }
  close(pipe_fds[1]);
  std::string errors;
  char buffer[4096];
  for (;;) {
    const ssize_t n = read(pipe_fds[0], buffer, sizeof(buffer));
    if (n > 0) {
      errors.append(buffer, static_cast<size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(pipe_fds[0]);
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  const std::string reason = LastLine(errors);
  if (!reason.empty()) throw InputError(reason);
  throw InputError(std::string("--plots: ") + kPython + " " + script + " failed (status " +
                   std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
}

}  // namespace auvdock::cli
