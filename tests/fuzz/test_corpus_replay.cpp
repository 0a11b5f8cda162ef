// Replays every committed fuzz input (tests/fuzz/seeds/<harness>: the seed corpora;
// tests/fuzz/corpus/<harness>: every crash the fuzzers found, kept as a regression) through
// the same entry functions the fuzzers run, without libFuzzer. Each input must load or be
// refused with an InputError; under the sanitizer build, also without a report.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "harnesses.h"
#include "src/core/error.h"

namespace lvox::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(const std::string& kind, std::string_view harness) {
  std::vector<fs::path> files;
  const fs::path dir = fs::path(LVOX_SOURCE_DIR) / "tests/fuzz" / kind / harness;
  if (fs::is_directory(dir))
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.is_regular_file()) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<uint8_t> readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Runs one input; returns "" when the entry returned or threw an InputError, else what
// went wrong.
std::string replay(Entry entry, const fs::path& file) {
  const std::vector<uint8_t> bytes = readBytes(file);
  try {
    entry(bytes.data(), bytes.size());
  } catch (const InputError&) {
  } catch (const std::exception& e) {
    return file.string() + ": " + typeid(e).name() + ": " + e.what();
  } catch (...) {
    return file.string() + ": a non-std exception";
  }
  return "";
}

}  // namespace

// Names the harness in test output (instead of its bytes).
void PrintTo(const Harness& h, std::ostream* os) { *os << h.name; }

namespace {

class CorpusReplay : public testing::TestWithParam<Harness> {};

TEST_P(CorpusReplay, SeedsAndCrashesLoadOrThrowInputError) {
  const Harness h = GetParam();
  const std::vector<fs::path> seeds = inputs("seeds", h.name);
  // Every harness has seeds: an empty list would mean a wrong path, not a pass.
  ASSERT_FALSE(seeds.empty()) << "no seeds for " << h.name;
  for (const std::string kind : {"seeds", "corpus"})
    for (const fs::path& file : inputs(kind, h.name)) EXPECT_EQ(replay(h.entry, file), "");
}

INSTANTIATE_TEST_SUITE_P(Fuzz, CorpusReplay, testing::ValuesIn(harnesses()),
                         [](const testing::TestParamInfo<Harness>& param) {
                           return std::string(param.param.name);
                         });

}  // namespace
}  // namespace lvox::fuzz
