// Run time against error, one PNG per sweep, drawn by gnuplot (Debian: gnuplot-nox, pngcairo
// terminal): x = the whole frame's median time, left panel y = RMS deviation from the converged
// reference, right panel y = P99 penetration into the body mesh. The Pareto front (no other point
// is both faster and more accurate) is drawn as a line, the default setting as a ringed point.
#pragma once

#include "results.h"

#include <string>
#include <vector>

namespace bench {

// Indices of rows on the Pareto front of (time, error): minimise both; sorted by time.
std::vector<size_t> paretoFront(const std::vector<double>& time, const std::vector<double>& error);

// Writes <dir>/<stem>.dat and <stem>.gp and runs gnuplot (found on PATH) to draw <stem>.png.
// Returns false with `note` set when gnuplot is missing or failed (the .gp script is kept).
bool plotSweep(const std::string& dir, const std::string& stem, const std::string& title, const std::vector<Row>& rows,
               std::string& note);

}  // namespace bench
