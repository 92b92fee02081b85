#include "tests/testing/run_command.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>

#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock::test {

namespace {

// ready: polled until it holds (then `signal` is sent), the child ends, or timeout_s passes.
CommandResult Run(const std::vector<std::string>& args, double delay_s, int signal,
                  const std::function<bool()>& ready = {}, double timeout_s = 0.0) {
  TempDir capture;
  const std::string out_path = capture / "out.txt", err_path = capture / "err.txt";
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, 1);
    ::dup2(err, 2);
    std::vector<char*> argv;
    std::string program = AUVDOCK_CLI_PATH;
    argv.push_back(program.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(program.c_str(), argv.data());
    std::_Exit(127);
  }
  int status = 0;
  bool reaped = false;
  if (signal != 0 && ready) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < deadline) {
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        reaped = true;
        break;
      }
      if (ready()) {
        ::kill(pid, signal);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  } else if (signal != 0) {
    std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));
    ::kill(pid, signal);
  }
  if (!reaped) ::waitpid(pid, &status, 0);
  CommandResult result;
  result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = ReadTextFile(out_path);
  result.err = ReadTextFile(err_path);
  return result;
}

}  // namespace

CommandResult RunAuvdock(const std::vector<std::string>& args) { return Run(args, 0.0, 0); }

CommandResult RunAuvdockAndSignal(const std::vector<std::string>& args, double delay_s,
                                  int signal) {
  return Run(args, delay_s, signal);
}

CommandResult RunAuvdockAndSignalWhen(const std::vector<std::string>& args,
                                      const std::function<bool()>& ready, int signal,
                                      double timeout_s) {
  return Run(args, 0.0, signal, ready, timeout_s);
}

std::string SimulateDetections(const std::string& folder, const std::string& name,
                               double duration_s, const std::string& extra_scenario) {
  const std::string scenario = folder + "/" + name + ".yaml";
  WriteTextFile(scenario, "name: " + name + "\nduration_s: " + std::to_string(duration_s) +
                              "\ndock: " + SourcePath("data/docks/t_shape.yaml") + "\n" +
                              extra_scenario);
  const std::string dataset = folder + "/" + name;
  const CommandResult r = RunAuvdock(
      {"simulate", "--scenario", scenario, "--out", dataset, "--detections-only", "--quiet"});
  if (r.exit_status != 0) throw std::runtime_error("simulate " + scenario + ": " + r.err);
  return dataset;
}

}  // namespace auvdock::test
