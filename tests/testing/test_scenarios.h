// Scenario factories for tests: the default scenario, shortened and shrunk so ctest stays fast.
#pragma once

#include <string>

#include "auvdock/sim/scenario.h"

namespace auvdock::test {

std::string SourcePath(const std::string& relative);  // path inside the source tree

// data/scenarios/default.yaml as shipped (40 s, 640x512).
Scenario DefaultScenario();
// The default scenario cut to `duration_s` seconds, with 160x128 images (same field of view).
Scenario ShortScenario(double duration_s = 2.0);
// data/scenarios/long_approach.yaml (30 m out, no light for its first ~35 s) cut to `duration_s`.
Scenario LongApproachScenario(double duration_s);

}  // namespace auvdock::test
