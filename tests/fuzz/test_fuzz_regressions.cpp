// Replays fuzz inputs through the fuzz targets (tests/fuzz/fuzz_*.cpp) in an ordinary GoogleTest:
//  - FuzzRegressions.*: every file under tests/fuzz/regressions/<target>/ - each input a fuzzer
//    once crashed on (or an edge case written by hand), kept so the bug stays fixed;
//  - FuzzSeeds.*: the seed corpora the build generates from ../shared/data (tests/fuzz/make_seeds.cpp).
// A target aborts (and fails the test) on a bug, so passing means no crash, no sanitizer report in
// the ASan build, no DRAPE_ERROR_INTERNAL and no non-finite output read after DRAPE_OK.
#include "fuzz_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using Target = int (*)(const uint8_t*, size_t);

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string()[0] != '.') out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

int replay(const fs::path& dir, Target target) {
  int n = 0;
  for (const fs::path& p : filesIn(dir)) {
    std::ifstream f(p, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    std::printf("[ replay   ] %s (%zu bytes)\n", p.filename().string().c_str(), bytes.size());
    std::fflush(stdout);
    target(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    ++n;
  }
  return n;
}

void regressions(const char* name, Target target) {
  // The empty input and a few bytes are always replayed as well.
  target(nullptr, 0);
  const uint8_t zeros[64] = {};
  target(zeros, sizeof zeros);
  const int n = replay(fs::path(DRAPE_FUZZ_REGRESSION_DIR) / name, target);
  std::printf("[ figures  ] %d committed inputs replayed for fuzz_%s\n", n, name);
}

void seeds(const char* name, Target target) {
  const int n = replay(fs::path(DRAPE_FUZZ_SEED_DIR) / name, target);
  if (n == 0) GTEST_SKIP() << "no seeds under " << DRAPE_FUZZ_SEED_DIR << "/" << name;
}

TEST(FuzzRegressions, Recording) { regressions("recording", drape_fuzz_recording); }
TEST(FuzzRegressions, Obj) { regressions("obj", drape_fuzz_obj); }
TEST(FuzzRegressions, Capi) { regressions("capi", drape_fuzz_capi); }
TEST(FuzzSeeds, Recording) { seeds("recording", drape_fuzz_recording); }
TEST(FuzzSeeds, Obj) { seeds("obj", drape_fuzz_obj); }
TEST(FuzzSeeds, Capi) { seeds("capi", drape_fuzz_capi); }

}  // namespace
