// A libFuzzer target: one parser of outside input (fuzz_parsers.h), named at compile time by
// AUVDOCK_FUZZ_PARSER (fuzz/CMakeLists.txt builds one target per parser). An InputError is the
// parser's contract for bad input; any other exception escaping is a finding: the target aborts
// and libFuzzer keeps the input. Crashes, hangs and sanitizer reports are findings by themselves.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "auvdock/io/input_error.h"
#include "fuzz/fuzz_parsers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    auvdock::fuzz::RunParser(AUVDOCK_FUZZ_PARSER, data, size);
  } catch (const auvdock::InputError&) {
    // The contract for bad input.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "auvdock fuzz: an exception other than InputError escaped: %s\n", e.what());
    std::abort();
  }
  return 0;
}
