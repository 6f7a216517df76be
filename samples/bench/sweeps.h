// The settings drape-bench sweeps: each sweep turns one knob (or two: substeps x iterations) away
// from the default setting and keeps everything else at the library's defaults.
#pragma once

#include "scenario.h"

#include <string>
#include <vector>

namespace bench {

struct Sweep {
  std::string name;   // CSV / PNG file stem
  std::string title;  // for plots and tables
  std::vector<Setting> settings;
};

// quick: the few points CI runs (docs/benchmarks.md lists both sets). with_opencl: add the
// OpenCL backend to the backend sweep (a run without a usable device notes it and goes on).
std::vector<Sweep> makeSweeps(bool quick, bool with_opencl);

// Names of all sweeps, for --sweeps and --help.
std::vector<std::string> sweepNames();

}  // namespace bench
