#include "tests/testing/test_scenarios.h"

namespace auvdock::test {

std::string SourcePath(const std::string& relative) {
  return std::string(AUVDOCK_SOURCE_DIR) + "/" + relative;
}

Scenario DefaultScenario() { return LoadScenario(SourcePath("data/scenarios/default.yaml")); }

Scenario LongApproachScenario(double duration_s) {
  Scenario s = LoadScenario(SourcePath("data/scenarios/long_approach.yaml"));
  s.duration_s = duration_s;
  return s;
}

Scenario ShortScenario(double duration_s) {
  Scenario s = DefaultScenario();
  s.duration_s = duration_s;
  s.cameras.width = 160;
  s.cameras.height = 128;
  return s;
}

}  // namespace auvdock::test
