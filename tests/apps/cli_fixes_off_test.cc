// End-to-end: acoustic fixes 50 m off the dock frame (converted from a beacon that is not where
// the dock is) while the lights are in view. The lights are believed: the gate refuses every
// fix, the window is not reset for them (no divergence), the go/no-go stays safe, and `run`
// warns that the fixes disagree (stderr and summary.json "warnings").
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"

using ::testing::HasSubstr;

namespace auvdock {
namespace {

TEST(FixesOffCli, LightsAreBelievedAndTheFixesWarnedOf) {
  test::TempDir tmp;
  const std::string dataset = test::SimulateDetections(tmp.path(), "lit", 30.0);
  // Every fix 50 m along D's x.
  std::istringstream in(test::ReadTextFile(dataset + "/usbl0/data.csv"));
  std::string line, shifted;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') {
      shifted += line + "\n";
      continue;
    }
    const size_t first = line.find(','), second = line.find(',', first + 1);
    const double x = std::stod(line.substr(first + 1, second - first - 1)) + 50.0;
    shifted += line.substr(0, first + 1) + std::to_string(x) + line.substr(second) + "\n";
  }
  test::WriteTextFile(dataset + "/usbl0/data.csv", shifted);

  const std::string out = tmp / "out";
  const auto r = test::RunAuvdock({"run", "--dataset", dataset, "--detections",
                                   dataset + "/detections.csv", "--out", out, "--quiet"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("acoustic fixes: they disagree with the lights"));
  const nlohmann::json summary = nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
  EXPECT_EQ(summary["divergences"].get<int>(), 0);
  EXPECT_EQ(summary["usbl_fixes"]["used"].get<int>(), 0);
  EXPECT_THAT(summary["warnings"].dump(), HasSubstr("dock frame D"));
  EXPECT_GT(summary["go_decisions"].get<int>(), 200);
  const auto e =
      test::RunAuvdock({"evaluate", "--dataset", dataset, "--estimate", out + "/trajectory.tum",
                        "--decisions", out + "/decisions.csv", "--json"});
  ASSERT_EQ(e.exit_status, 0) << e.err;
  const nlohmann::json report = nlohmann::json::parse(e.out);
  EXPECT_EQ(report.at("decisions").at("n_go_unsafe").get<int>(), 0);
  EXPECT_LT(report.at("pos_rmse_m").get<double>(), 0.05);
}

}  // namespace
}  // namespace auvdock
