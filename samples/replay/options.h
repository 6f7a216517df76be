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
  // --garment-fit: by-kind (default) = a SHAPE context and the garment's cut BY_KIND; shape /
  // skeleton = that context fit, followed by the garment (cut CONTEXT).
  int32_t garment_fit = DRAPE_GARMENT_FIT_SHAPE;
  int32_t garment_cut = DRAPE_GARMENT_CUT_BY_KIND;
  double arm_clearance_m = -1.0;   // --arm-clearance M: [0, 0.05] m; < 0: the library default
  bool arms_on_bones = false;      // --arm-clearance off: drape_context_desc.arms_clear_torso 0
  uint32_t fidelity_every = 10;    // measure proxy fidelity every N updated frames; 0: never

  // The garment (--garment). kind is a drape_garment_kind for a template; garment_none turns the
  // cloth off (push + drape_context_update, as before garments existed); a non-empty garment_obj
  // is an OBJ file added with drape_context_add_garment_obj_file and the default drape_mesh_fit.
  bool garment_none = false;
  int32_t garment_kind = DRAPE_GARMENT_TSHIRT;
  // --under G: a template garment worn under the main one (drape_garment_set_layer: it 1, the main
  // garment 2; docs/garments.md "Layered garments"); under_kind -1 = none.
  int32_t under_kind = -1;
  std::string garment_obj;
  uint32_t particles = 0;          // 0: the library's template default (drape_garment_template_init)
  int32_t solver = DRAPE_SOLVER_XPBD;
  bool solver_given = false;
  uint32_t substeps = 0;           // per 1/30 s frame; 0: the library default (or 2880 Hz for massspring)
  uint32_t iterations = 0;         // XPBD passes per substep, [1, 64]; 0: the library default (1)
  double strain_limit = -1.0;      // XPBD strain limit, [0, 10]; < 0: the library default (0.1)
  int32_t strain_limit_passes = 0; // XPBD strain-limit passes, [1, 16]; 0: the library default (2)
  int32_t collision_stride = -1;   // XPBD collision every N substeps, [0, 8]; < 0: the library default (0: by resolution)
  uint32_t measure_every = 1;      // drape_garment_measure every N stepped frames; 0: never
  bool measure_given = false;
  std::string out_dir = "drape-out";
  bool out_given = false;
  bool write_obj = true;
  std::string stats_path;          // empty: see resolveStatsPath
  bool quiet = false;
  bool help = false;
  // --full-pipeline: every stage every frame, no proxy culling, no sleeping
  // (drape_pipeline_options all off), to compare with the adaptive default.
  bool full_pipeline = false;

  // Pictures (render.h): frames every N updated frames (0 = none), the views, the size of one view.
  bool render = true;              // --no-render: false
  uint32_t render_every = 0;       // only when render_every_given; else about 30 frames per take
  bool render_every_given = false;
  std::string camera = "both";     // sensor | side | both
  uint32_t width = 480, height = 640;
  bool render_options_given = false;  // --camera or --size
  std::string backend = "cpu";     // "cpu" or "opencl" (drape_context_set_backend)
};

// Parses argv. On a bad argument returns false and sets `error` to a one-line message saying what
// to do (without the "drape-replay: error: " prefix).
bool parseOptions(int argc, const char* const* argv, Options& out, std::string& error);

// Where the stats JSON goes: --stats if given, else DIR/stats.json when OBJs are written or --out
// was given, else nowhere (empty string).
std::string resolveStatsPath(const Options& options);

// How often frames are rendered for a replay of `frames` frames: 0 (none) with --no-render or
// --render-every 0, or with --no-obj and no --out unless --render-every was given (a timing run
// writes no files); --render-every N as given; else max(1, frames / 30), about 30 pictures a take.
uint32_t resolveRenderEvery(const Options& options, uint32_t frames);

// The name of a garment template kind as --garment spells it ("tshirt", "longsleeve", ...).
const char* garmentKindName(int32_t kind);
// "xpbd" or "massspring".
const char* solverName(int32_t solver);

// The --help text.
std::string helpText();

}  // namespace replay
