// End-to-end: a depth sensor whose zero is not the dock survey's (the simulator's depth.bias_m).
// `run` and `smooth` taken at its word warn that the depth gate rejects most samples (stderr and
// summary.json "warnings"); with `estimate_depth_offset: true` they estimate the offset (in
// summary.json "depth_offset"), use the samples and warn of nothing; without an offset nothing is
// said either. The simulator lists the offset in groundtruth/faults.csv.
#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/testing/run_command.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace auvdock {
namespace {

std::string Simulate(const test::TempDir& tmp, const std::string& name, double bias_m) {
  const std::string scenario = tmp / (name + ".yaml");
  test::WriteTextFile(scenario, "name: " + name + "\nduration_s: 16.0\ndock: " +
                                    test::SourcePath("data/docks/t_shape.yaml") +
                                    "\ndepth: {bias_m: " + std::to_string(bias_m) + "}\n");
  const std::string dataset = tmp / name;
  const auto r = test::RunAuvdock(
      {"simulate", "--scenario", scenario, "--out", dataset, "--detections-only", "--quiet"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return dataset;
}

nlohmann::json Summary(const std::string& out) {
  return nlohmann::json::parse(test::ReadTextFile(out + "/summary.json"));
}

TEST(DepthOffsetCli, AnOffsetIsWarnedOfOrEstimated) {
  test::TempDir tmp;
  const std::string biased = Simulate(tmp, "biased", 0.3);
  const std::string plain = Simulate(tmp, "plain", 0.0);
  EXPECT_THAT(test::ReadTextFile(biased + "/groundtruth/faults.csv"),
              HasSubstr("depth0,bias,bias_m=0.3"));
  EXPECT_THAT(test::ReadTextFile(plain + "/groundtruth/faults.csv"), Not(HasSubstr(",bias,")));
  const std::string config = tmp / "offset.yaml";
  test::WriteTextFile(config, "estimator:\n  estimate_depth_offset: true\n");

  for (const std::string command : {"run", "smooth"}) {
    const auto run = [&](const std::string& dataset, const std::string& out, bool offset) {
      std::vector<std::string> args = {command, "--dataset", dataset, "--detections",
                                       dataset + "/detections.csv", "--out", out, "--quiet"};
      if (offset) args.insert(args.end(), {"--config", config});
      const auto r = test::RunAuvdock(args);
      EXPECT_EQ(r.exit_status, 0) << command << ": " << r.err;
      return r;
    };
    // Taken at its word: a large share of the samples gated (more than the quarter that the
    // warning takes; the DVL's vertical bias, a state since 2026-12-07, explains part of the
    // offset as a slow drift at first), and a warning that says what to do.
    const std::string at_word = tmp / (command + "_at_word");
    const auto r1 = run(biased, at_word, false);
    EXPECT_THAT(r1.err, HasSubstr("estimate_depth_offset")) << command;
    const nlohmann::json s1 = Summary(at_word);
    const int gated = s1["depth_samples"]["gated"].get<int>();
    EXPECT_GT(3 * gated, gated + s1["depth_samples"]["used"].get<int>()) << command;
    EXPECT_THAT(s1["warnings"].dump(), HasSubstr("estimate_depth_offset")) << command;
    EXPECT_FALSE(s1.contains("depth_offset")) << command;

    // Estimated: found to a few centimetres, every sample used, no warning.
    const std::string estimated = tmp / (command + "_estimated");
    const auto r2 = run(biased, estimated, true);
    EXPECT_THAT(r2.err, Not(HasSubstr("estimate_depth_offset"))) << command;
    const nlohmann::json s2 = Summary(estimated);
    ASSERT_TRUE(s2.contains("depth_offset")) << command;
    EXPECT_NEAR(s2["depth_offset"]["m"].get<double>(), 0.3, 0.03) << command;
    EXPECT_LT(s2["depth_offset"]["sigma_m"].get<double>(), 0.03) << command;
    EXPECT_LT(std::abs(s2["depth_offset"]["m"].get<double>() - 0.3),
              3.0 * s2["depth_offset"]["sigma_m"].get<double>() + 0.005)
        << command;
    EXPECT_LE(s2["depth_samples"]["gated"].get<int>(), 2) << command;

    // A sensor at the survey's zero: nothing to warn of.
    const std::string fine = tmp / (command + "_plain");
    const auto r3 = run(plain, fine, false);
    EXPECT_THAT(r3.err, Not(HasSubstr("estimate_depth_offset"))) << command;
  }
}

}  // namespace
}  // namespace auvdock
