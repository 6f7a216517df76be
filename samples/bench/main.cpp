// drape-bench: run time against error for every setting that trades one for the other, over real
// recordings, with Bullet's soft body as a peer in the same run. Writes one CSV and one PNG per
// sweep, bullet_peer.csv and summary.md into --out. Method and results: docs/benchmarks.md.
#include <drape/drape.h>

#include "bullet_peer.h"
#include "energy.h"
#include "metrics.h"
#include "plot.h"
#include "report.h"
#include "results.h"
#include "scenario.h"
#include "sweeps.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#ifndef DRAPE_BENCH_BUNDLED_TAKE
#define DRAPE_BENCH_BUNDLED_TAKE ""
#endif
#ifndef DRAPE_SHARED_DATA_DIR
#define DRAPE_SHARED_DATA_DIR ""
#endif

namespace fs = std::filesystem;
using namespace bench;

namespace {

constexpr int kExitOk = 0, kExitFailure = 1, kExitUsage = 2;

struct TakeSpec {
  std::string path;
  uint32_t stride = 1;
};

struct Options {
  bool quick = false;
  bool help = false;
  bool bullet = true;
  double bullet_field_m = bench::kBulletFieldM;  // the peer's distance-field voxel
  int peer_spread = 0;  // extra Bullet 4 x 10 runs per peer take and setting, each from another starting shirt
  bool plots = true;
  std::string out = "drape-bench-out";
  std::vector<TakeSpec> takes;
  double seconds = 0;         // per take; 0 = mode default
  int repeats = 0;            // 0 = mode default
  double energy_seconds = 0;  // 0 = mode default
  std::set<std::string> sweeps;
};

const char* kHelp =
    "usage: drape-bench [--quick] [--out DIR] [--take PATH[@STRIDE]]... [--seconds S] [--repeats N]\n"
    "                   [--sweeps a,b,...] [--energy-seconds S] [--no-bullet] [--bullet-field M]\n"
    "                   [--peer-spread N]\n"
    "                   [--no-plots]\n"
    "Sweeps Drape's speed/accuracy settings over real takes and writes, into DIR (default\n"
    "drape-bench-out): <sweep>.csv and <sweep>.png per sweep, table1.csv, references.csv (the\n"
    "converged references' own errors), bullet_peer.csv, summary.md.\n"
    "  --quick           a few points per sweep, one 1 s take, one repeat (CI: under a minute)\n"
    "  --take PATH@N     a recording (Kinect CSV, BVH, .drec), replaying every N-th frame;\n"
    "                    default: the shared Kinect take and the CMU BVH hop take at 60 Hz\n"
    "                    (the bundled Kinect take with --quick or without ../shared/data)\n"
    "  --seconds S       seconds of each take to replay (default 5, quick 1)\n"
    "  --repeats N       timed repeats per setting (default 3, quick 1)\n"
    "  --sweeps LIST     subset of: solver,substeps,iterations,strain_limit,ring_points,\n"
    "                    contact_response,continuous_collision,resolution,backend\n"
    "  --energy-seconds S  free-hanging energy-drift run length (default 2, quick 0.5)\n"
    "  --no-bullet       skip the Bullet peer;  --no-plots  skip gnuplot\n"
    "  --bullet-field M  the Bullet peer's distance-field voxel in metres, [0.005, 1] (default 0.05;\n"
    "                    a full run also runs 4 x 10 at Bullet's own 0.25 and at 0.02)\n"
    "  --peer-spread N   Bullet 4 x 10 N more times per peer take and Drape setting, its free nodes\n"
    "                    starting shifted 0.5 mm from where Drape placed them (seeds 1..N), [0, 20]\n"
    "                    (default 0): the spread of Bullet's figures and how often Drape's are below\n"
    "                    them\n";

bool parseNumber(const std::string& s, double lo, double hi, double& out) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !(v >= lo && v <= hi)) return false;
  out = v;
  return true;
}

bool parse(int argc, char** argv, Options& o, std::string& err) {
  const std::vector<std::string> names = sweepNames();
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](std::string& v) {
      if (i + 1 >= argc) {
        err = a + " needs a value";
        return false;
      }
      v = argv[++i];
      return true;
    };
    std::string v;
    double d = 0;
    if (a == "--quick")
      o.quick = true;
    else if (a == "--help" || a == "-h")
      o.help = true;
    else if (a == "--no-bullet")
      o.bullet = false;
    else if (a == "--no-plots")
      o.plots = false;
    else if (a == "--out") {
      if (!value(o.out)) return false;
    } else if (a == "--take") {
      if (!value(v)) return false;
      TakeSpec t;
      const size_t at = v.rfind('@');
      t.path = v.substr(0, at);
      if (at != std::string::npos) {
        if (!parseNumber(v.substr(at + 1), 1, 100, d)) return err = "--take " + v + ": stride must be 1..100", false;
        t.stride = static_cast<uint32_t>(d);
      }
      o.takes.push_back(t);
    } else if (a == "--seconds") {
      if (!value(v) || !parseNumber(v, 0.1, 3600, o.seconds)) return err = "--seconds must be in [0.1, 3600]", false;
    } else if (a == "--energy-seconds") {
      if (!value(v) || !parseNumber(v, 0.05, 600, o.energy_seconds))
        return err = "--energy-seconds must be in [0.05, 600]", false;
    } else if (a == "--repeats") {
      if (!value(v) || !parseNumber(v, 1, 100, d)) return err = "--repeats must be in [1, 100]", false;
      o.repeats = static_cast<int>(d);
    } else if (a == "--peer-spread") {
      if (!value(v) || !parseNumber(v, 0, 20, d) || d != std::floor(d))
        return err = "--peer-spread must be a whole number in [0, 20]", false;
      o.peer_spread = static_cast<int>(d);
    } else if (a == "--bullet-field") {
      if (!value(v) || !parseNumber(v, 0.005, 1, o.bullet_field_m))
        return err = "--bullet-field must be in [0.005, 1] (metres)", false;
    } else if (a == "--sweeps") {
      if (!value(v)) return false;
      std::stringstream ss(v);
      std::string s;
      while (std::getline(ss, s, ',')) {
        if (std::find(names.begin(), names.end(), s) == names.end()) return err = "unknown sweep '" + s + "'", false;
        o.sweeps.insert(s);
      }
    } else {
      err = "unknown argument '" + a + "' (see --help)";
      return false;
    }
  }
  return true;
}

// A measuring run's figures into a row: its garment's size and its error figures.
void takeFigures(const RunResult& m, Row& r) {
  r.particles = m.particles;
  r.substeps_per_frame = m.substeps_per_frame;
  r.stretch_p99 = m.stretch_p99;
  r.stretch_max = m.stretch_max;
  r.pen_p99_mm = m.penetration_p99_mm;
  r.pen_max_mm = m.penetration_max_mm;
  r.deeper_than_2mm = m.deeper_than_2mm;
  r.in_body = m.in_body;
  r.inside_mean = m.inside_mean;
  r.inside_max = m.inside_max;
  r.openings_off = m.openings_off;
  r.nan_resets = m.nan_resets;
}

// A converged reference's row: its error figures by the settings' meters, no times (it is not
// timed). Labelled by the setting that first asked for it: "reference of <label> (<sweep>)".
Row referenceRow(const Take& take, const Setting& asked_by, const Setting& ref, const RunResult& rr) {
  Row r;
  r.setting = ref;
  r.setting.label = "reference of " + asked_by.label + " (" + asked_by.sweep + ")";
  r.take = take.name;
  r.rate_hz = take.rate_hz;
  takeFigures(rr, r);
  return r;
}

struct Runner {
  const Options& opt;
  int repeats;
  double energy_seconds;
  std::map<std::string, Row> done;              // key + take -> row
  std::map<std::string, RunResult> references;  // reference key + take
  // The references' own error figures, in the order they were run: what the same model reaches
  // when the solver has converged (summary.md, "What solver effort reaches").
  std::vector<Row> reference_rows;
  std::map<std::string, EnergyDrift> energies;  // solver/hz/iterations/particles

  bool row(const Take& take, const Setting& s, Row& out, std::string& err) {
    const std::string id = s.key() + "|" + take.name;
    auto hit = done.find(id);
    if (hit != done.end()) {
      out = hit->second;
      out.setting = s;
      return true;
    }
    const auto t0 = std::chrono::steady_clock::now();
    Row r;
    r.setting = s;
    r.take = take.name;
    r.rate_hz = take.rate_hz;
    r.repeats = repeats;
    // Measuring run: every frame's vertices and error figures (outside the timed calls).
    RunResult measured;
    RunOptions mo;
    mo.measure = true;
    mo.keep_positions = true;
    if (!runDrape(take, s, mo, measured, err)) return false;
    takeFigures(measured, r);
    r.device = measured.device;
    // The converged reference of the same model (Setting::convergedReference).
    const Setting ref = s.convergedReference(opt.quick);
    const std::string ref_id = ref.key() + "|" + take.name;
    if (!references.count(ref_id)) {
      RunResult rr;
      RunOptions ro;
      ro.keep_positions = true;
      ro.measure = true;  // by the same meters as the settings (outside any timed call)
      std::fprintf(stderr, "drape-bench:   reference %s ...\n", ref.key().c_str());
      if (!runDrape(take, ref, ro, rr, err)) return false;
      reference_rows.push_back(referenceRow(take, s, ref, rr));
      references[ref_id] = std::move(rr);
    }
    const RunResult& rr = references[ref_id];
    DeviationMeter dev;
    for (size_t f = 0; f < measured.positions.size() && f < rr.positions.size(); ++f)
      dev.addFrame(measured.positions[f].data(), rr.positions[f].data(), measured.positions[f].size());
    r.dev_rms_mm = dev.rmsMm();
    r.dev_max_mm = dev.maxMm();
    // Timed repeats.
    std::vector<FrameTimes> frames;
    for (int k = 0; k < repeats; ++k) {
      RunResult timed;
      if (!runDrape(take, s, RunOptions{}, timed, err)) return false;
      frames.insert(frames.end(), timed.times.begin(), timed.times.end());
    }
    fillTimes(frames, take.rate_hz, r);
    // Energy drift of the free-hanging garment (independent of the take and the body proxies).
    char ekey[128];
    std::snprintf(ekey, sizeof ekey, "%d %g %u %g %u %u", s.solver, s.substep_hz, s.iterations, s.strain_limit,
                  s.strain_limit_passes, s.particles);
    if (!energies.count(ekey)) {
      EnergyDrift e;
      if (!energyDrift(s, energy_seconds, e, err)) return false;
      energies[ekey] = e;
    }
    r.energy = energies[ekey];
    done[id] = r;
    out = r;
    std::fprintf(stderr, "drape-bench: %-22s %-22s %-16s frame %.3f ms, dev %.2f mm, pen P99 %.2f mm (%.1f s)\n",
                 s.sweep.c_str(), s.label.c_str(), take.name.c_str(), r.frame.median, r.dev_rms_mm, r.pen_p99_mm,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    return true;
  }
};

std::string commandLine(int argc, char** argv) {
  std::string c = "drape-bench";
  for (int i = 1; i < argc; ++i) c += std::string(" ") + argv[i];
  return c;
}

int run(int argc, char** argv) {
  Options opt;
  std::string err;
  if (!parse(argc, argv, opt, err)) {
    std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
    return kExitUsage;
  }
  if (opt.help) {
    std::fputs(kHelp, stdout);
    return kExitOk;
  }
  const auto start = std::chrono::steady_clock::now();
  const double seconds = opt.seconds > 0 ? opt.seconds : (opt.quick ? 1.0 : 5.0);
  const int repeats = opt.repeats > 0 ? opt.repeats : (opt.quick ? 1 : 3);
  const double energy_seconds = opt.energy_seconds > 0 ? opt.energy_seconds : (opt.quick ? 0.5 : 2.0);
  if (opt.takes.empty()) {
    const fs::path shared(DRAPE_SHARED_DATA_DIR);
    const fs::path kinect = shared / "kinect_v2_msft_labanotation/Ges01_wavehand.csv";
    const fs::path bvh = shared / "cmu_mocap_bvh/scaled_131_03.bvh";
    if (!opt.quick && fs::exists(kinect) && fs::exists(bvh)) {
      opt.takes.push_back({kinect.string(), 1});
      opt.takes.push_back({bvh.string(), 2});  // 120 Hz mocap replayed at 60 Hz
    } else {
      opt.takes.push_back({DRAPE_BENCH_BUNDLED_TAKE, 1});
    }
  }
  std::vector<Take> takes;
  for (const TakeSpec& ts : opt.takes) {
    Take probe;
    if (!loadTake(ts.path, 3, ts.stride, probe, err)) {
      std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
      return kExitUsage;
    }
    Take t;
    const auto frames = static_cast<uint32_t>(std::max(3.0, std::round(seconds * probe.rate_hz)));
    if (!loadTake(ts.path, frames, ts.stride, t, err)) {
      std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
      return kExitUsage;
    }
    takes.push_back(std::move(t));
  }
  std::error_code ec;
  fs::create_directories(opt.out, ec);
  if (!fs::is_directory(opt.out)) {
    std::fprintf(stderr, "drape-bench: error: cannot create --out directory '%s'\n", opt.out.c_str());
    return kExitUsage;
  }

  ReportInput report;
  report.command = commandLine(argc, argv);
  report.takes = takes;
  report.energy_seconds = energy_seconds;
  Runner runner{opt, repeats, energy_seconds, {}, {}, {}, {}};
  for (const Sweep& sw : makeSweeps(opt.quick, true)) {
    if (!opt.sweeps.empty() && !opt.sweeps.count(sw.name)) continue;
    std::vector<Row> rows;
    for (const Take& t : takes) {
      for (const Setting& s : sw.settings) {
        Row r;
        if (!runner.row(t, s, r, err)) {
          if (s.backend != "cpu") {  // no usable device here: say so, measure the rest
            report.notes.push_back("backend " + s.backend + " on " + t.name + " not measured: " + err);
            std::fprintf(stderr, "drape-bench: note: %s\n", report.notes.back().c_str());
            continue;
          }
          std::fprintf(stderr, "drape-bench: error: %s / %s on %s: %s\n", sw.name.c_str(), s.label.c_str(),
                       t.name.c_str(), err.c_str());
          return kExitFailure;
        }
        rows.push_back(r);
      }
    }
    if (!writeRowsCsv((fs::path(opt.out) / (sw.name + ".csv")).string(), rows, err)) {
      std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
      return kExitFailure;
    }
    std::string note;
    if (opt.plots && !plotSweep(opt.out, sw.name, sw.title, rows, note)) report.notes.push_back(note);
    report.sweeps.push_back(sw);
    report.rows.push_back(std::move(rows));
  }
  // The paper's Table 1: the default setting at the template size closest to 2 000 particles.
  uint32_t table1_target = Setting{}.particles;
  if (!templateTargetFor(2000, table1_target, err)) {
    std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
    return kExitFailure;
  }
  for (const Take& t : takes) {
    Setting s;
    s.sweep = "table1";
    s.label = "default at ~2000 particles";
    s.particles = table1_target;
    Row r;
    if (!runner.row(t, s, r, err)) {
      std::fprintf(stderr, "drape-bench: error: Table 1 run on %s: %s\n", t.name.c_str(), err.c_str());
      return kExitFailure;
    }
    report.table1.push_back(r);
  }
  if (!writeRowsCsv((fs::path(opt.out) / "table1.csv").string(), report.table1, err)) {
    std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
    return kExitFailure;
  }
  report.references = runner.reference_rows;
  if (!writeRowsCsv((fs::path(opt.out) / "references.csv").string(), report.references, err)) {
    std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
    return kExitFailure;
  }

  if (opt.bullet && !bulletAvailable()) {
    std::string why;
    PeerResult unused;
    runBulletPeer(takes[0], 0, 0, 0, opt.bullet_field_m, PeerDriver{}, unused, why);
    report.peer_note = why;
    std::fprintf(stderr, "drape-bench: note: %s\n", why.c_str());
  } else if (opt.bullet) {
    report.peer_field_m = opt.bullet_field_m;
    // (substeps per 1/60 s, iterations, distance-field voxel): the peer's field for both settings,
    // and in a full run 4 x 10 also on Bullet's own 0.25 m field and on a finer 2 cm one, which
    // show what the field buys (docs/benchmarks.md, "The Bullet peer's distance field").
    struct PeerSetting {
      int substeps, iterations;
      double field_m;
    };
    const double f = opt.bullet_field_m;
    std::vector<PeerSetting> settings = {{4, 10, f}};
    if (!opt.quick) {
      settings = {{1, 10, f}, {4, 10, f}};
      for (double extra : {kBulletDefaultFieldM, 0.02})
        if (extra != f) settings.push_back({4, 10, extra});
    }
    // Every take in a full run (the BVH take is replayed at 60 Hz, the rate Bullet's and NvCloth's
    // figures are quoted for); the first one with --quick.
    const size_t peer_takes = opt.quick ? 1 : takes.size();
    // Bullet 4 x 10 on the peer's field once per Drape setting, started from that setting's shirt
    // (Bullet's stretch follows the shirt it starts from); the other Bullet settings from the
    // default's.
    const std::vector<PeerDriver> drivers = peerDrivers();
    auto isTarget = [&](const PeerSetting& ps) { return ps.substeps == 4 && ps.iterations == 10 && ps.field_m == f; };
    for (size_t ti = 0; ti < peer_takes; ++ti) {
      for (const PeerSetting& ps : settings) {
        for (size_t di = 0; di < (isTarget(ps) ? drivers.size() : 1); ++di) {
          PeerResult p;
          const auto t0 = std::chrono::steady_clock::now();
          if (!runBulletPeer(takes[ti], table1_target, ps.substeps, ps.iterations, ps.field_m, drivers[di], p, err)) {
            std::fprintf(stderr, "drape-bench: error: Bullet peer: %s\n", err.c_str());
            return kExitFailure;
          }
          std::fprintf(stderr, "drape-bench: Bullet %s on %s: %.2f CPU ms per frame, Drape (%s) %.3f: %.0fx (%.1f s)\n",
                       p.label.c_str(), p.take.c_str(), median(p.bullet.cpu_ms), p.driver.label.c_str(),
                       median(p.drape.cpu_ms), median(p.bullet.cpu_ms) / median(p.drape.cpu_ms),
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
          report.peers.push_back(p);
        }
      }
      // --peer-spread: Bullet 4 x 10 on the peer's field again from other starting shirts, per setting.
      for (const PeerDriver& driver : drivers) {
        for (int seed = 1; seed <= opt.peer_spread; ++seed) {
          PeerResult p;
          if (!runBulletPeer(takes[ti], table1_target, 4, 10, f, driver, p, err, static_cast<uint32_t>(seed))) {
            std::fprintf(stderr, "drape-bench: error: Bullet peer: %s\n", err.c_str());
            return kExitFailure;
          }
          std::fprintf(stderr, "drape-bench: Bullet %s on %s from Drape's %s shirt: stretch P99 %.2f %%, penetration P99 %.2f mm\n",
                       p.label.c_str(), p.take.c_str(), driver.label.c_str(), 100.0 * p.bullet.stretch_p99,
                       p.bullet.penetration_p99_mm);
          report.spread.push_back(p);
        }
      }
    }
    if (!writePeerCsv((fs::path(opt.out) / "bullet_peer.csv").string(), report.peers, err) ||
        (!report.spread.empty() &&
         !writePeerCsv((fs::path(opt.out) / "bullet_spread.csv").string(), report.spread, err))) {
      std::fprintf(stderr, "drape-bench: error: %s\n", err.c_str());
      return kExitFailure;
    }
  } else {
    report.peer_note = "Skipped (--no-bullet).";
  }
  const std::string summary = (fs::path(opt.out) / "summary.md").string();
  std::ofstream(summary) << renderReport(report);
  std::fprintf(stderr, "drape-bench: wrote %s (%.1f s in all)\n", summary.c_str(),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "drape-bench: error: %s\n", e.what());
    return kExitFailure;
  }
}
