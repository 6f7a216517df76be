// Where the tests find real data: ../shared/data beside the checkout (or $DRAPE_SHARED_DATA).
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace drape::test {

inline std::string sharedDataDir() {
  if (const char* env = std::getenv("DRAPE_SHARED_DATA")) return env;
  return DRAPE_SHARED_DATA_DIR;
}

// Full path of a file under the shared data folder, or "" when it is absent.
inline std::string sharedFile(const std::string& relative) {
  const std::filesystem::path p = std::filesystem::path(sharedDataDir()) / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

// A parameterised test's name for a shared file: the file's stem, every character but letters and
// digits made '_' ("cmu_mocap_bvh/scaled_131_01.bvh" -> "scaled_131_01"), so CTest's names stay
// the same from run to run and patterns such as "*/Ges02*" select takes.
inline std::string takeTestName(const std::string& relative) {
  std::string name = std::filesystem::path(relative).stem().string();
  std::replace_if(name.begin(), name.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)); }, '_');
  return name;
}

}  // namespace drape::test

// Skips the current test with a clear message when a shared data file is missing.
#define DRAPE_REQUIRE_SHARED(var, relative)                                                   \
  const std::string var = ::drape::test::sharedFile(relative);                               \
  if (var.empty()) {                                                                          \
    GTEST_SKIP() << "shared data file '" << (relative) << "' not found under "               \
                 << ::drape::test::sharedDataDir() << " (set DRAPE_SHARED_DATA)";            \
  }
