// The parsers of outside input against their fuzzing corpus (fuzz/fuzz_parsers.h,
// scripts/fuzz.sh): the seeds, files as auvdock writes them, parse; every input that a fuzzer
// once found crashing a parser or escaping it with an exception other than InputError
// (tests/data/fuzz_regressions/PARSER/) is now bad input with a clear error, or parses. Under
// scripts/sanitize.sh the same runs catch memory errors.
#include "fuzz/fuzz_parsers.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <utility>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"

namespace auvdock {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = AUVDOCK_SOURCE_DIR;

std::vector<uint8_t> ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// Files in folder (none when it does not exist), sorted.
std::vector<fs::path> FilesIn(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::is_directory(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// The parsers' scratch folder goes when the tests are done.
class RemoveScratchFolder : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code error;
    fs::remove_all(fuzz::ScratchFolder(), error);
  }
};
const ::testing::Environment* const kRemoveScratchFolder =
    ::testing::AddGlobalTestEnvironment(new RemoveScratchFolder);

TEST(FuzzCorpus, EverySeedFolderBelongsToAParser) {
  const std::vector<std::string>& names = fuzz::ParserNames();
  for (const auto& entry : fs::directory_iterator(kSource / "fuzz" / "seeds")) {
    if (!entry.is_directory()) continue;
    const std::string name = entry.path().filename().string();
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
  for (const auto& entry : fs::directory_iterator(kSource / "tests" / "data" / "fuzz_regressions")) {
    if (!entry.is_directory()) continue;
    const std::string name = entry.path().filename().string();
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
}

// The seeds of scripts/fuzz.sh: fuzz/seeds/PARSER, the shipped scenarios, estimator options and
// docks, and the EuRoC sample's sensor.yaml files behind their selector byte.
std::vector<std::vector<uint8_t>> Seeds(const std::string& parser) {
  std::vector<std::vector<uint8_t>> seeds;
  for (const fs::path& file : FilesIn(kSource / "fuzz" / "seeds" / parser)) {
    seeds.push_back(ReadBytes(file));
  }
  const std::map<std::string, std::string> shipped{
      {"scenario", "data/scenarios"}, {"run_config", "data/estimator"}, {"dock", "data/docks"}};
  if (const auto it = shipped.find(parser); it != shipped.end()) {
    for (const fs::path& file : FilesIn(kSource / it->second)) seeds.push_back(ReadBytes(file));
  }
  if (parser == "euroc_sensor_yaml") {
    const fs::path mav0 = kSource / "tests" / "data" / "euroc_mini" / "mav0";
    for (const auto& [selector, sensor] : {std::pair<uint8_t, const char*>{0, "cam0"}, {1, "imu0"}}) {
      std::vector<uint8_t> bytes{selector};
      const std::vector<uint8_t> text = ReadBytes(mav0 / sensor / "sensor.yaml");
      bytes.insert(bytes.end(), text.begin(), text.end());
      seeds.push_back(bytes);
    }
  }
  return seeds;
}

TEST(FuzzCorpus, EveryParserHasSeedsAndTheyParse) {
  for (const std::string& parser : fuzz::ParserNames()) {
    const std::vector<std::vector<uint8_t>> seeds = Seeds(parser);
    EXPECT_FALSE(seeds.empty()) << parser;
    for (size_t i = 0; i < seeds.size(); ++i) {
      EXPECT_NO_THROW(fuzz::RunParser(parser, seeds[i].data(), seeds[i].size()))
          << parser << ": seed " << i;
    }
  }
}

TEST(FuzzCorpus, AnUnknownParserIsRefused) {
  const uint8_t byte = 0;
  EXPECT_THROW(fuzz::RunParser("no_such_parser", &byte, 1), std::invalid_argument);
}

TEST(FuzzCorpus, EveryFindingIsNowBadInputOrParses) {
  for (const std::string& parser : fuzz::ParserNames()) {
    for (const fs::path& file : FilesIn(kSource / "tests" / "data" / "fuzz_regressions" / parser)) {
      const std::vector<uint8_t> bytes = ReadBytes(file);
      try {
        fuzz::RunParser(parser, bytes.data(), bytes.size());
      } catch (const InputError& e) {
        EXPECT_FALSE(std::string(e.what()).empty()) << parser << ": " << file.filename();
      } catch (const std::exception& e) {
        ADD_FAILURE() << parser << ": " << file.filename() << ": not an InputError: " << e.what();
      }
    }
  }
}

}  // namespace
}  // namespace auvdock
