// Where the tests find real data: ../shared/data beside the checkout (or $DRAPE_SHARED_DATA).
#pragma once

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

}  // namespace drape::test

// Skips the current test with a clear message when a shared data file is missing.
#define DRAPE_REQUIRE_SHARED(var, relative)                                                   \
  const std::string var = ::drape::test::sharedFile(relative);                               \
  if (var.empty()) {                                                                          \
    GTEST_SKIP() << "shared data file '" << (relative) << "' not found under "               \
                 << ::drape::test::sharedDataDir() << " (set DRAPE_SHARED_DATA)";            \
  }
