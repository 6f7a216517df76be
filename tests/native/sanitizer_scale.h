// Under AddressSanitizer + UndefinedBehaviorSanitizer (preset asan) every test runs; the few whose
// cost is the repetition of one check (more random samples, more frames of a converging
// simulation, more garments through the same fit) repeat less there, and those whose check does
// not depend on the garment's size dress a smaller one (kSanitizedBuild). The sanitizers look for
// memory and undefined-behaviour errors in the code a repetition runs, and the first repetitions
// run all of it; the release suite keeps the full counts (docs/robustness.md, "Sanitizers").
#pragma once

#include <algorithm>

namespace drape::test {

#if defined(DRAPE_SANITIZED_BUILD)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif

// `n` in a plain build; under the sanitizers `n / divisor`, at least 1.
constexpr int repeatsUnderSanitizers(int n, int divisor) {
  return kSanitizedBuild ? std::max(1, n / divisor) : n;
}

}  // namespace drape::test
