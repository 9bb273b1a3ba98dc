// Replays a fuzz target's committed inputs under GoogleTest, so the seed corpus and every input
// that once crashed (regressions/) run in the normal and the sanitizer test suites without
// libFuzzer. A crash aborts this test; another exception than InputError fails it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
extern const char* const kFuzzTargetName;  // generated per target by tests/fuzz/CMakeLists.txt

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(const std::string& folder) {
  const fs::path dir = fs::path(CLUMPKIT_SOURCE_DIR) / "tests" / "fuzz" / folder / kFuzzTargetName;
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename() != ".gitkeep") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

void replay(const std::vector<fs::path>& files) {
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    std::ifstream in(f, std::ios::binary);
    ASSERT_TRUE(in) << "cannot read " << f;
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    EXPECT_NO_THROW(
        LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
  }
}

TEST(FuzzReplay, SeedCorpus) {
  const auto files = inputs("corpus");
  EXPECT_GE(files.size(), 3u) << "every fuzz target needs a committed seed corpus";
  replay(files);
}

TEST(FuzzReplay, Regressions) {
  replay(inputs("regressions"));
}

}  // namespace
