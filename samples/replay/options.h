// drape-replay command line: parsed options and the help text.
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <string>

namespace replay {

struct Options {
  std::string recording;           // empty: the bundled recording
  int32_t layout = DRAPE_LAYOUT_AUTO;
  drape_body_shape shape{};        // filled by drape_body_shape_init, then --body keys
  bool body_given = false;
  uint32_t max_frames = 0;         // 0: every frame of the recording
  uint32_t ring_points = 0;        // 0: the library default
  int32_t proxy_rule = DRAPE_PROXY_RULE_DRAPE;
  uint32_t fidelity_every = 10;    // measure proxy fidelity every N updated frames; 0: never
  std::string out_dir = "drape-out";
  bool out_given = false;
  bool write_obj = true;
  std::string stats_path;          // empty: see resolveStatsPath
  bool quiet = false;
  bool help = false;
};

// Parses argv. On a bad argument returns false and sets `error` to a one-line message saying what
// to do (without the "drape-replay: error: " prefix).
bool parseOptions(int argc, const char* const* argv, Options& out, std::string& error);

// Where the stats JSON goes: --stats if given, else DIR/stats.json when OBJs are written or --out
// was given, else nowhere (empty string).
std::string resolveStatsPath(const Options& options);

// The --help text.
std::string helpText();

}  // namespace replay
