// auvdock: the single command line of the project. Wiring only; the work is in the library.
//
// Exit status: 0 on success, 2 on bad input or a usage error (one line on stderr), 1 on an
// unexpected internal error, 130 when interrupted.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/commands.h"
#include "apps/heap_settings.h"
#include "apps/unknown_words.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/cancellation.h"

int main(int argc, char** argv) {
  // Each frame's image buffers stay in the heap for the next (apps/heap_settings.h: detection on
  // the pool clip 43.5 -> 9.4 ms per frame, where page faults took 38 % of the time).
  auvdock::cli::ApplyHeapSettings();
  CLI::App app{"auvdock: state estimation for the close-range phase of AUV recovery"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "auvdock 0.1.0");
  auvdock::cli::AddSimulateCommand(app);
  auvdock::cli::AddEvaluateCommand(app);
  auvdock::cli::AddFrontendCommand(app);
  auvdock::cli::AddPnpCommand(app);
  auvdock::cli::AddRunCommand(app);
  auvdock::cli::AddSmoothCommand(app);
  auvdock::cli::AddCrlbCommand(app);
  auvdock::cli::AddDetectCommand(app);
  auvdock::cli::AddDemoCommand(app);

  const std::string unknown =
      auvdock::cli::UnknownWordMessage(app, std::vector<std::string>(argv + 1, argv + argc));
  if (!unknown.empty()) {
    std::fprintf(stderr, "auvdock: error: %s\n", unknown.c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::fprintf(stderr, "auvdock: error: %s (see --help)\n", e.what());
    return 2;
  } catch (const auvdock::Cancelled& e) {
    std::fprintf(stderr, "auvdock: interrupted: %s\n", e.what());
    return 130;
  } catch (const auvdock::InputError& e) {
    std::fprintf(stderr, "auvdock: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "auvdock: internal error: %s\n", e.what());
    return 1;
  }
  return 0;
}
