// The OpenCL sources of /opencl, embedded at build time (cmake/embed_opencl.cmake writes the
// definitions into the build tree): names and texts in the order the program concatenates them.
#pragma once

#include <cstddef>

namespace drape {

struct ClSourceFile {
  const char* name;
  const char* text;
};

extern const ClSourceFile kClSources[];
extern const size_t kClSourceCount;

}  // namespace drape
