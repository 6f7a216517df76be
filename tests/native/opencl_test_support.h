// Shared by the OpenCL tests: one runtime (device choice + program build) per test binary, since
// PoCL takes seconds to compile the kernels; tests skip with the reason when no OpenCL device
// works (no platform installed, or the program does not build on it).
#pragma once

#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_runtime.h"
#endif

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace drape::test {

#if DRAPE_HAVE_OPENCL
// The shared runtime, or null with `why` (stable across calls).
inline std::shared_ptr<ClRuntime> sharedClRuntime(std::string* why = nullptr) {
  static std::string reason;
  static std::shared_ptr<ClRuntime> rt = [] {
    ClChoice c;
    std::string err;
    auto r = ClRuntime::create(c, err);
    if (!r) reason = err;
    return r;
  }();
  if (why) *why = reason;
  return rt;
}
#endif

}  // namespace drape::test

// Skips the current test (with the reason) when no OpenCL device can run the kernels.
#if DRAPE_HAVE_OPENCL
#define DRAPE_REQUIRE_OPENCL(rt)                                                        \
  std::string drape_cl_why_;                                                            \
  auto rt = ::drape::test::sharedClRuntime(&drape_cl_why_);                             \
  if (!rt) GTEST_SKIP() << "no usable OpenCL device: " << drape_cl_why_
#else
#define DRAPE_REQUIRE_OPENCL(rt) GTEST_SKIP() << "built without OpenCL (DRAPE_HAVE_OPENCL off)"
#endif
