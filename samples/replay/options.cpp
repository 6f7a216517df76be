// drape-replay command line parsing. Strict: unknown options, unknown --body keys, malformed or
// out-of-range numbers are errors (exit 2), never silently ignored or clamped.
#include "options.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace replay {

namespace {

// A whole-string decimal number (no trailing garbage, finite).
bool parseDouble(const std::string& text, double& out) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (errno == ERANGE || end != text.c_str() + text.size() || !std::isfinite(v)) return false;
  out = v;
  return true;
}

// A whole-string unsigned decimal integer in [lo, hi].
bool parseUint(const std::string& text, unsigned long lo, unsigned long hi, uint32_t& out) {
  if (text.empty()) return false;
  for (char c : text)
    if (c < '0' || c > '9') return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
  if (errno == ERANGE || end != text.c_str() + text.size() || v < lo || v > hi) return false;
  out = static_cast<uint32_t>(v);
  return true;
}

bool endsWithObj(const std::string& text) {
  if (text.size() < 5) return false;  // at least one character before ".obj"
  std::string ext = text.substr(text.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".obj";
}

struct GarmentName { const char* name; int32_t kind; };
constexpr GarmentName kGarmentNames[] = {
    {"tshirt", DRAPE_GARMENT_TSHIRT},   {"longsleeve", DRAPE_GARMENT_LONG_SLEEVE},
    {"skirt", DRAPE_GARMENT_SKIRT},     {"dress", DRAPE_GARMENT_DRESS},
    {"trousers", DRAPE_GARMENT_TROUSERS}};

// Substeps per 1/30 s frame: substep_hz = 30 * N must stay within the library's [30, 20000].
constexpr unsigned long kMaxSubsteps = 666;

// An option with two named values (`a` -> va, `b` -> vb): sets `out`, or says what was expected.
bool parseChoice(const std::string& name, const std::string& value, const char* a, int32_t va, const char* b,
                 int32_t vb, int32_t& out, std::string& error, const char* note = "") {
  if (value == a || value == b) {
    out = value == a ? va : vb;
    return true;
  }
  error = name + " '" + value + "' is not '" + a + "' or '" + b + "'" + note;
  return false;
}

bool parseLayout(const std::string& text, int32_t& out) {
  if (text == "auto") out = DRAPE_LAYOUT_AUTO;
  else if (text == "kinect1") out = DRAPE_LAYOUT_KINECT1;
  else if (text == "kinect2") out = DRAPE_LAYOUT_KINECT2;
  else if (text == "azure") out = DRAPE_LAYOUT_AZURE;
  else return false;
  return true;
}

// --body key=value[,key=value...] on top of the shape already in `shape`.
bool parseBody(const std::string& spec, drape_body_shape& shape, std::string& error) {
  struct Field { const char* key; float* value; };
  const Field fields[] = {
      {"height_m", &shape.height_m},   {"weight_kg", &shape.weight_kg},
      {"neck_mm", &shape.neck_mm},     {"chest_mm", &shape.chest_mm},
      {"waist_mm", &shape.waist_mm},   {"hip_mm", &shape.hip_mm},
      {"thigh_mm", &shape.thigh_mm},   {"calf_mm", &shape.calf_mm},
      {"upper_arm_mm", &shape.upper_arm_mm}, {"forearm_mm", &shape.forearm_mm}};
  const std::string hint =
      "; expected key=value pairs separated by commas, keys: sex (female|male|unspecified), height_m, "
      "weight_kg, neck_mm, chest_mm, waist_mm, hip_mm, thigh_mm, calf_mm, upper_arm_mm, forearm_mm "
      "(e.g. --body height_m=1.70,weight_kg=65)";
  if (spec.empty()) {
    error = "--body needs a value" + hint;
    return false;
  }
  size_t start = 0;
  while (start <= spec.size()) {
    const size_t comma = spec.find(',', start);
    const std::string item = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? spec.size() + 1 : comma + 1;
    const size_t eq = item.find('=');
    if (item.empty() || eq == std::string::npos || eq == 0) {
      error = "--body item '" + item + "' is not key=value" + hint;
      return false;
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "sex") {
      if (value == "female") shape.sex = DRAPE_SEX_FEMALE;
      else if (value == "male") shape.sex = DRAPE_SEX_MALE;
      else if (value == "unspecified") shape.sex = DRAPE_SEX_UNSPECIFIED;
      else {
        error = "--body sex='" + value + "' is not female, male or unspecified";
        return false;
      }
      continue;
    }
    const Field* field = nullptr;
    for (const Field& f : fields)
      if (key == f.key) field = &f;
    if (!field) {
      error = "--body key '" + key + "' is unknown" + hint;
      return false;
    }
    double v = 0.0;
    if (!parseDouble(value, v) || std::fabs(v) > 1e6) {
      error = "--body " + key + "='" + value + "' is not a number (e.g. " + key + "=" +
              (key == "height_m" ? "1.70" : key == "weight_kg" ? "65" : "780") + ")";
      return false;
    }
    *field->value = static_cast<float>(v);
  }
  return true;
}

}  // namespace

bool parseOptions(int argc, const char* const* argv, Options& o, std::string& error) {
  drape_body_shape_init(&o.shape);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    // Accept both "--opt value" and "--opt=value".
    std::string name = arg, value;
    bool inline_value = false;
    if (arg.rfind("--", 0) == 0) {
      const size_t eq = arg.find('=');
      if (eq != std::string::npos) {
        name = arg.substr(0, eq);
        value = arg.substr(eq + 1);
        inline_value = true;
      }
    }
    auto flag = [&]() {
      if (inline_value) {
        error = name + " takes no value; drop '=" + value + "'";
        return false;
      }
      return true;
    };
    auto takeValue = [&]() {
      if (inline_value) return true;
      if (i + 1 >= argc) {
        error = name + " needs a value; see drape-replay --help";
        return false;
      }
      value = argv[++i];
      return true;
    };

    if (name == "--help" || name == "-h") {
      if (!flag()) return false;
      o.help = true;
    } else if (name == "--quiet" || name == "-q") {
      if (!flag()) return false;
      o.quiet = true;
    } else if (name == "--no-obj") {
      if (!flag()) return false;
      o.write_obj = false;
    } else if (name == "--full-pipeline") {
      if (!flag()) return false;
      o.full_pipeline = true;
    } else if (name == "--recording") {
      if (!takeValue()) return false;
      if (value.empty()) {
        error = "--recording needs a file path (Kinect v2 CSV, BVH or .drec)";
        return false;
      }
      o.recording = value;
    } else if (name == "--layout") {
      if (!takeValue()) return false;
      if (!parseLayout(value, o.layout)) {
        error = "--layout '" + value + "' is not one of kinect1, kinect2, azure, auto";
        return false;
      }
    } else if (name == "--body") {
      if (!takeValue() || !parseBody(value, o.shape, error)) return false;
      o.body_given = true;
    } else if (name == "--frames") {
      if (!takeValue()) return false;
      if (!parseUint(value, 1, 0xffffffffUL, o.max_frames)) {
        error = "--frames '" + value + "' is not a whole number >= 1 (e.g. --frames 100)";
        return false;
      }
    } else if (name == "--ring-points") {
      if (!takeValue()) return false;
      if (!parseUint(value, 1, 0xffffffffUL, o.ring_points)) {
        error = "--ring-points '" + value + "' is not a whole number (a multiple of 4 in [8, 256], e.g. 20)";
        return false;
      }
    } else if (name == "--proxy-rule") {
      if (!takeValue() ||
          !parseChoice(name, value, "paper", DRAPE_PROXY_RULE_PAPER, "drape", DRAPE_PROXY_RULE_DRAPE, o.proxy_rule, error))
        return false;
    } else if (name == "--arm-clearance") {
      if (!takeValue()) return false;
      double v = 0.0;
      if (value == "off") {
        o.arms_on_bones = true;
      } else if (parseDouble(value, v) && v >= 0.0 && v <= 0.05) {
        o.arm_clearance_m = v;
        o.arms_on_bones = false;
      } else {
        error = "--arm-clearance '" + value +
                "' is neither 'off' nor a gap in metres in [0, 0.05] (kept between the arms' rings and the torso's)";
        return false;
      }
    } else if (name == "--garment-fit") {
      if (!takeValue()) return false;
      if (value == "by-kind") {
        o.garment_fit = DRAPE_GARMENT_FIT_SHAPE;
        o.garment_cut = DRAPE_GARMENT_CUT_BY_KIND;
      } else if (parseChoice(name, value, "shape", DRAPE_GARMENT_FIT_SHAPE, "skeleton", DRAPE_GARMENT_FIT_SKELETON,
                             o.garment_fit, error)) {
        o.garment_cut = DRAPE_GARMENT_CUT_CONTEXT;
      } else {
        error = "--garment-fit '" + value + "' is not 'by-kind', 'shape' or 'skeleton'";
        return false;
      }
    } else if (name == "--fidelity-every") {
      if (!takeValue()) return false;
      if (!parseUint(value, 0, 0xffffffffUL, o.fidelity_every)) {
        error = "--fidelity-every '" + value + "' is not a whole number >= 0 (0 turns the measurement off)";
        return false;
      }
    } else if (name == "--garment") {
      if (!takeValue()) return false;
      o.garment_none = false;
      o.garment_obj.clear();
      bool known = false;
      for (const GarmentName& g : kGarmentNames)
        if (value == g.name) {
          o.garment_kind = g.kind;
          known = true;
        }
      if (value == "none") {
        o.garment_none = true;
      } else if (!known) {
        if (!endsWithObj(value)) {
          error = "--garment '" + value +
                  "' is not tshirt, longsleeve, skirt, dress, trousers, none or a path ending in .obj "
                  "(e.g. --garment skirt or --garment shirt.obj)";
          return false;
        }
        o.garment_obj = value;
      }
    } else if (name == "--under") {
      if (!takeValue()) return false;
      o.under_kind = -1;
      for (const GarmentName& g : kGarmentNames)
        if (value == g.name) o.under_kind = g.kind;
      if (o.under_kind < 0) {
        error = "--under '" + value + "' is not tshirt, longsleeve, skirt, dress or trousers (e.g. --under trousers)";
        return false;
      }
    } else if (name == "--particles") {
      if (!takeValue()) return false;
      if (!parseUint(value, 200, 200000, o.particles)) {
        error = "--particles '" + value + "' is not a whole number in [200, 200000] (e.g. --particles 8000)";
        return false;
      }
    } else if (name == "--solver") {
      if (!takeValue() || !parseChoice(name, value, "xpbd", DRAPE_SOLVER_XPBD, "massspring", DRAPE_SOLVER_MASS_SPRING,
                                       o.solver, error, " (the paper's mass-spring)"))
        return false;
      o.solver_given = true;
    } else if (name == "--substeps") {
      if (!takeValue()) return false;
      if (!parseUint(value, 1, kMaxSubsteps, o.substeps)) {
        error = "--substeps '" + value + "' is not a whole number in [1, " + std::to_string(kMaxSubsteps) +
                "] (substeps per 1/30 s frame, e.g. --substeps 10 for 300 Hz)";
        return false;
      }
    } else if (name == "--iterations") {
      if (!takeValue()) return false;
      if (!parseUint(value, 1, 64, o.iterations)) {
        error = "--iterations '" + value +
                "' is not a whole number in [1, 64] (XPBD constraint passes per substep; 1 is the method)";
        return false;
      }
    } else if (name == "--strain-limit") {
      if (!takeValue()) return false;
      double v = 0.0;
      if (!parseDouble(value, v) || !(v >= 0.0 && v <= 10.0)) {
        error = "--strain-limit '" + value +
                "' is not a number in [0, 10] (structural edges are held to rest * (1 + it) at the end of "
                "each step; 0 turns the limit off)";
        return false;
      }
      o.strain_limit = v;
    } else if (name == "--strain-limit-passes") {
      if (!takeValue()) return false;
      uint32_t v = 0;
      if (!parseUint(value, 1, 16, v)) {
        error = "--strain-limit-passes '" + value +
                "' is not a whole number in [1, 16] (Gauss-Seidel passes of the strain limit at the end of each step)";
        return false;
      }
      o.strain_limit_passes = static_cast<int32_t>(v);
    } else if (name == "--collision-stride") {
      if (!takeValue()) return false;
      uint32_t v = 0;
      if (!parseUint(value, 0, 8, v)) {
        error = "--collision-stride '" + value +
                "' is not a whole number in [0, 8] (collision every N substeps; 0 = by the garment's resolution)";
        return false;
      }
      o.collision_stride = static_cast<int32_t>(v);
    } else if (name == "--measure-every" || name == "--garment-every") {
      if (!takeValue()) return false;
      if (!parseUint(value, 0, 0xffffffffUL, o.measure_every)) {
        error = name + " '" + value + "' is not a whole number >= 0 (1 = every frame; 0 turns the measurement off)";
        return false;
      }
      o.measure_given = true;
    } else if (name == "--no-render") {
      if (!flag()) return false;
      o.render = false;
    } else if (name == "--render-every") {
      if (!takeValue()) return false;
      if (!parseUint(value, 0, 0xffffffffUL, o.render_every)) {
        error = "--render-every '" + value + "' is not a whole number >= 0 (e.g. --render-every 5; 0 = no pictures)";
        return false;
      }
      o.render_every_given = true;
    } else if (name == "--camera") {
      if (!takeValue()) return false;
      if (value != "sensor" && value != "side" && value != "both") {
        error = "--camera '" + value + "' is not sensor, side or both (e.g. --camera sensor)";
        return false;
      }
      o.camera = value;
      o.render_options_given = true;
    } else if (name == "--size") {
      if (!takeValue()) return false;
      const size_t x = value.find_first_of("xX");
      if (x == std::string::npos || !parseUint(value.substr(0, x), 64, 4096, o.width) ||
          !parseUint(value.substr(x + 1), 64, 4096, o.height)) {
        error = "--size '" + value + "' is not WIDTHxHEIGHT with each in [64, 4096] pixels (e.g. --size 480x640)";
        return false;
      }
      o.render_options_given = true;
    } else if (name == "--backend") {
      if (!takeValue()) return false;
      if (value != "cpu" && value != "opencl") {
        error = "--backend '" + value + "' is not a backend; use --backend cpu (the default) or opencl";
        return false;
      }
      o.backend = value;
    } else if (name == "--out") {
      if (!takeValue()) return false;
      if (value.empty()) {
        error = "--out needs a directory path";
        return false;
      }
      o.out_dir = value;
      o.out_given = true;
    } else if (name == "--stats") {
      if (!takeValue()) return false;
      if (value.empty()) {
        error = "--stats needs a file path (e.g. --stats stats.json)";
        return false;
      }
      o.stats_path = value;
    } else {
      error = "unknown argument '" + arg + "'; run drape-replay --help for the options";
      return false;
    }
  }
  // Garment options that the chosen garment would silently ignore are mistakes.
  if (o.garment_none && (o.particles != 0 || o.solver_given || o.substeps != 0 || o.iterations != 0 ||
                         o.strain_limit >= 0.0 || o.strain_limit_passes > 0 || o.collision_stride >= 0 ||
                         o.measure_given)) {
    error = std::string(o.particles != 0 ? "--particles" : o.solver_given ? "--solver"
                        : o.substeps != 0 ? "--substeps" : o.iterations != 0 ? "--iterations"
                        : o.strain_limit >= 0.0 ? "--strain-limit"
                        : o.strain_limit_passes > 0 ? "--strain-limit-passes"
                        : o.collision_stride >= 0 ? "--collision-stride" : "--measure-every") +
            " has no effect with --garment none; drop it or choose a garment";
    return false;
  }
  if (o.under_kind >= 0 && o.garment_none) {
    error = "--under needs a garment to be worn over it; drop --garment none";
    return false;
  }
  if (o.strain_limit >= 0.0 && o.solver == DRAPE_SOLVER_MASS_SPRING) {
    error = "--strain-limit has no effect with --solver massspring (an XPBD setting); drop it";
    return false;
  }
  if (o.strain_limit_passes > 0 && o.solver == DRAPE_SOLVER_MASS_SPRING) {
    error = "--strain-limit-passes has no effect with --solver massspring (an XPBD setting); drop it";
    return false;
  }
  if (o.strain_limit_passes > 0 && o.strain_limit == 0.0) {
    error = "--strain-limit-passes has no effect with --strain-limit 0 (the limit is off); drop one";
    return false;
  }
  if (o.collision_stride >= 0 && o.solver == DRAPE_SOLVER_MASS_SPRING) {
    error = "--collision-stride has no effect with --solver massspring (it collides every substep); drop it";
    return false;
  }
  if (o.iterations != 0 && o.solver == DRAPE_SOLVER_MASS_SPRING) {
    error = "--iterations has no effect with --solver massspring (it has no constraint passes); drop it";
    return false;
  }
  if (!o.render && (o.render_every_given || o.render_options_given)) {
    error = std::string(o.render_every_given ? "--render-every" : o.camera != "both" ? "--camera" : "--size") +
            " has no effect with --no-render; drop one of them";
    return false;
  }
  if (!o.garment_obj.empty() && o.particles != 0) {
    error = "--particles sets a template garment's resolution; an OBJ garment keeps its own vertices, "
            "so drop --particles or use --garment tshirt|longsleeve|skirt|dress|trousers";
    return false;
  }
  return true;
}

const char* garmentKindName(int32_t kind) {
  for (const GarmentName& g : kGarmentNames)
    if (g.kind == kind) return g.name;
  return "unknown";
}

const char* solverName(int32_t solver) {
  return solver == DRAPE_SOLVER_MASS_SPRING ? "massspring" : "xpbd";
}

uint32_t resolveRenderEvery(const Options& o, uint32_t frames) {
  if (!o.render) return 0;
  if (o.render_every_given) return o.render_every;
  if (!o.write_obj && !o.out_given) return 0;
  return std::max<uint32_t>(1, frames / 30);
}

std::string resolveStatsPath(const Options& o) {
  if (!o.stats_path.empty()) return o.stats_path;
  if (o.write_obj || o.out_given) {
    std::string dir = o.out_dir;
    if (!dir.empty() && dir.back() != '/' && dir.back() != '\\') dir += '/';
    return dir + "stats.json";
  }
  return std::string();
}

std::string helpText() {
  return
      "drape-replay: replays a skeleton recording through Drape, dresses the person in a garment and\n"
      "reports timing, mesh checks and cloth accuracy.\n"
      "\n"
      "Usage: drape-replay [options]\n"
      "With no options it replays the bundled Kinect v2 recording (Ges01_wavehand.csv) on the\n"
      "default body (1.70 m, 65 kg) in a 2 000-particle T-shirt and writes body_NNNNN.obj,\n"
      "garment_NNNNN.obj, pictures (render_NNNNN.png, contact_sheet.png, replay.gif) and\n"
      "stats.json into ./drape-out. A progress bar shows on a terminal for runs over a second.\n"
      "\n"
      "Options (\"--opt value\" or \"--opt=value\"):\n"
      "  --recording PATH      Kinect v2 CSV, BVH or Drape .drec file (format detected from content)\n"
      "  --layout L            layout hint: kinect1|kinect2|azure|auto (default auto)\n"
      "  --body K=V,...        body shape keys: sex (female|male|unspecified), height_m, weight_kg,\n"
      "                        neck_mm, chest_mm, waist_mm, hip_mm, thigh_mm, calf_mm,\n"
      "                        upper_arm_mm, forearm_mm (girths left out are predicted)\n"
      "  --frames N            replay at most N frames (N >= 1; default: all)\n"
      "  --ring-points K       points per feature ring: multiple of 4 in [8, 256] (default 20)\n"
      "  --proxy-rule R        tracking ellipsoids: drape (default) or paper (the paper's eq. 5-6)\n"
      "  --arm-clearance M     gap kept between the arms' rings and the torso's, in [0, 0.05] m\n"
      "                        (default 0.01), or off (every ring centred on its bone)\n"
      "  --fidelity-every N    measure how closely the ellipsoids fit the body every N frames\n"
      "                        (default 10; 0 = never; about 10 ms per measurement)\n"
      "  --garment G           tshirt (default), longsleeve, skirt, dress, trousers, none (no cloth:\n"
      "                        push + update only), or PATH.obj (a garment mesh, e.g. from MakeHuman)\n"
      "  --under G             a template garment (tshirt, longsleeve, skirt, dress, trousers)\n"
      "                        worn under the --garment one, which lies on it (layers 1 and 2:\n"
      "                        docs/garments.md \"Layered garments\"); same --particles and\n"
      "                        cloth options; drawn, written (under_NNNNN.obj) and measured\n"
      "  --particles N         template garment resolution, in [200, 200000] (default 2000;\n"
      "                        below ~500, ~300 for a T-shirt, limbs leave their tubes)\n"
      "  --garment-fit F       by-kind (default: trousers and long-sleeve tops as skeleton, the\n"
      "                        others as shape), shape (the body shape's standard proportions) or\n"
      "                        skeleton (once the bone lengths are calibrated, the garment is cut\n"
      "                        again for this person's bones and torso)\n"
      "  --solver S            xpbd (default) or massspring (the paper's mass-spring; it needs\n"
      "                        ~3 kHz, so it runs at 2880 Hz unless --substeps is given)\n"
      "  --substeps N          cloth substeps per 1/30 s frame, in [1, 666]: substep_hz = 30 * N\n"
      "                        (default 10 = 300 Hz for xpbd, 96 = 2880 Hz for massspring)\n"
      "  --iterations N        XPBD constraint passes per substep, in [1, 64] (default 1, the\n"
      "                        method; with --substeps, e.g. --substeps 160 --iterations 4 is\n"
      "                        drape-bench's converged reference)\n"
      "  --strain-limit F      XPBD: at the end of each step, structural edges longer than\n"
      "                        rest * (1 + F) are pulled back to that length, F in [0, 10]\n"
      "                        (default 0.1; 0 = off)\n"
      "  --strain-limit-passes N  XPBD: Gauss-Seidel passes of that limit, in [1, 16] (default 2;\n"
      "                        more passes with a tighter limit stretch less and cost ~4 us each\n"
      "                        at 2 000 particles, e.g. --strain-limit 0.05 --strain-limit-passes 8)\n"
      "  --collision-stride N  XPBD: collide with the ellipsoids every N substeps, N in [0, 8]\n"
      "                        (default 0: every substep for a garment of 300 to 1 250\n"
      "                        particles, every second one outside)\n"
      "  --measure-every N     measure the garment's accuracy (stretch, ellipsoid and body\n"
      "                        penetration; ~0.6 ms per 1 000 particles) every N frames (default 1;\n"
      "                        0 = never). Alias: --garment-every\n"
      "  --out DIR             output directory for body_NNNNN.obj, garment_NNNNN.obj and stats.json\n"
      "                        (default ./drape-out; created if missing)\n"
      "  --no-obj              do not write OBJ files (for timing)\n"
      "  --stats FILE.json     stats file (default DIR/stats.json; with --no-obj and no --out: none)\n"
      "  --render-every N      draw a picture every N frames: DIR/render_NNNNN.png, plus\n"
      "                        contact_sheet.png (12 frames across the take) and replay.gif\n"
      "                        (and replay.mp4 when ffmpeg is on PATH). Default: about 30 per\n"
      "                        take (frames / 30); 0 = none\n"
      "  --camera C            sensor (the sensor's view, mirrored like a mirror), side (from the\n"
      "                        person's right) or both side by side (default)\n"
      "  --size WxH            size of one view in pixels, each in [64, 4096] (default 480x640)\n"
      "  --no-render           no pictures at all (same as --render-every 0)\n"
      "  --backend B           cloth backend: cpu (the default) or opencl (the XPBD step on an OpenCL\n"
      "                        device, a GPU first; falls back to cpu with the reason when none works)\n"
      "  --full-pipeline       run every stage every frame: no proxy culling, no sleeping garments\n"
      "                        (the adaptive pipeline is the default; docs/adaptive.md)\n"
      "  --quiet, -q           no summary on stdout, no progress bar\n"
      "  --help, -h            this text\n"
      "\n"
      "Examples:\n"
      "  drape-replay\n"
      "  drape-replay --recording take.csv --frames 100 --out /tmp/take\n"
      "  drape-replay --camera sensor --size 720x960 --render-every 1 --no-obj --out /tmp/pics\n"
      "  drape-replay --no-render --no-obj --stats timing.json\n"
      "  drape-replay --body sex=female,height_m=1.62,weight_kg=58,waist_mm=720 --no-obj --stats s.json\n"
      "  drape-replay --recording scaled_131_03.bvh --ring-points 32 --no-obj --quiet --stats bvh.json\n"
      "  drape-replay --garment dress --particles 8000 --no-obj --stats dress.json\n"
      "  drape-replay --solver massspring --garment tshirt --frames 60 --no-obj --stats paper.json\n"
      "  drape-replay --garment ../shared/data/garments_makehuman_cc0/female_casualsuit02.obj \\\n"
      "               --body sex=female --frames 100\n"
      "  drape-replay --garment none --no-obj --stats body-only.json\n"
      "\n"
      "Exit codes: 0 replay ran (rejected frames are counted, not fatal); 2 bad arguments or an\n"
      "unreadable/unparsable recording; 1 any other failure. Details: docs/replay.md\n";
}

}  // namespace replay
