#include "results.h"

#include "metrics.h"

#include <cstdio>
#include <memory>

namespace bench {

namespace {

StageTime stage(const std::vector<FrameTimes>& frames, double FrameTimes::*field) {
  std::vector<double> v;
  v.reserve(frames.size());
  for (const FrameTimes& f : frames) v.push_back(f.*field);
  return StageTime{median(v), percentile(v, 90.0)};
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

// Text fields hold no comma (labels and take names are ours or file stems): a plain split parses.
std::string csvText(std::string s) {
  for (char& c : s)
    if (c == ',' || c == '\n' || c == '"') c = ';';
  return s;
}

const char* solverName(int32_t s) { return s == DRAPE_SOLVER_MASS_SPRING ? "mass-spring" : "xpbd"; }
const char* responseName(int32_t r) { return r == DRAPE_CONTACT_RADIAL ? "radial" : "exact"; }

}  // namespace

void fillTimes(const std::vector<FrameTimes>& frames, double rate_hz, Row& row) {
  row.timed_frames = frames.size();
  row.frame = stage(frames, &FrameTimes::frame);
  row.skeleton = stage(frames, &FrameTimes::skeleton);
  row.body = stage(frames, &FrameTimes::body);
  row.proxies = stage(frames, &FrameTimes::proxies);
  row.cloth = stage(frames, &FrameTimes::cloth);
  row.integrate = stage(frames, &FrameTimes::integrate);
  row.collide = stage(frames, &FrameTimes::collide);
  row.ms_per_sim_s = row.frame.median * rate_hz;
}

bool writeRowsCsv(const std::string& path, const std::vector<Row>& rows, std::string& error) {
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "w"));
  if (!f) {
    error = "cannot write " + path;
    return false;
  }
  // Text columns first (sweep .. backend), every later column numeric.
  std::fputs(
      "sweep,label,take,solver,contact_response,backend,is_default,rate_hz,substep_hz,iterations,"
      "ring_points,continuous_collision,strain_limit,strain_limit_passes,particles,repeats,timed_frames,"
      "substeps_per_frame,"
      "frame_ms_median,frame_ms_p90,skeleton_ms_median,skeleton_ms_p90,body_ms_median,body_ms_p90,"
      "proxies_ms_median,proxies_ms_p90,cloth_ms_median,cloth_ms_p90,integrate_ms_median,integrate_ms_p90,"
      "collide_ms_median,collide_ms_p90,ms_per_sim_s,dev_rms_mm,dev_max_mm,stretch_p99_pct,stretch_max_pct,"
      "pen_p99_mm,pen_max_mm,deeper_2mm_pct,inside_mean,inside_max,energy_drift,energy_worst,"
      "energy_exploded,nan_resets,openings_off_pct,in_body_pct\n",
      f.get());
  for (const Row& r : rows) {
    const Setting& s = r.setting;
    std::fprintf(f.get(),
                 "%s,%s,%s,%s,%s,%s,%d,%.4g,%g,%u,%u,%u,%g,%u,%u,%d,%zu,%.4g,"
                 "%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,"
                 "%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%u,%.5g,%.5g,%d,%u,%.4g,%.5g\n",
                 csvText(s.sweep).c_str(), csvText(s.label).c_str(), csvText(r.take).c_str(), solverName(s.solver),
                 responseName(s.contact_response), csvText(s.backend).c_str(), s.is_default ? 1 : 0, r.rate_hz, s.substep_hz,
                 s.iterations, s.ring_points, s.continuous_collision, s.strain_limit, s.strain_limit_passes,
                 r.particles, r.repeats,
                 r.timed_frames,
                 r.substeps_per_frame, r.frame.median, r.frame.p90, r.skeleton.median, r.skeleton.p90, r.body.median,
                 r.body.p90, r.proxies.median, r.proxies.p90, r.cloth.median, r.cloth.p90, r.integrate.median,
                 r.integrate.p90, r.collide.median, r.collide.p90, r.ms_per_sim_s, r.dev_rms_mm, r.dev_max_mm,
                 100.0 * r.stretch_p99, 100.0 * r.stretch_max, r.pen_p99_mm, r.pen_max_mm, 100.0 * r.deeper_than_2mm,
                 r.inside_mean, r.inside_max, r.energy.drift, r.energy.worst, r.energy.exploded ? 1 : 0, r.nan_resets,
                 100.0 * r.openings_off, 100.0 * r.in_body);
  }
  if (std::ferror(f.get())) {
    error = "error writing " + path;
    return false;
  }
  return true;
}

std::vector<PeerDriver> peerDrivers() {
  auto label = [](uint32_t iterations, float limit, uint32_t passes) {
    char its[32] = "";
    if (iterations > 1) std::snprintf(its, sizeof its, "%u iterations + ", iterations);
    char l[96];
    std::snprintf(l, sizeof l, "%sstrain limit %g %% x %u passes", its, 100.0 * limit, passes);
    return std::string(l);
  };
  return {PeerDriver{"default"},
          PeerDriver{label(0, kLessStretchLimit, kLessStretchPasses), 0, kLessStretchLimit, kLessStretchPasses},
          PeerDriver{label(kPeerIterations, kPeerLimit, kPeerPasses), kPeerIterations, kPeerLimit, kPeerPasses}};
}

bool writePeerCsv(const std::string& path, const std::vector<PeerResult>& peers, std::string& error) {
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "w"));
  if (!f) {
    error = "cannot write " + path;
    return false;
  }
  // cpu_*: thread CPU time (Bullet: stepSimulation; Drape: push + whole step); wall_*: wall time
  // (Bullet: stepSimulation; Drape: its garment step as drape_garment_get_stats reports it).
  // Two rows per peer run: Bullet, started from the shirt of Drape at drape_setting, and Drape at
  // that setting (the driver); bullet_over_drape_*: Bullet over that Drape, on both rows.
  std::fputs(
      "engine,setting,drape_setting,take,rate_hz,particles,substeps_per_60hz,iterations,frames,cpu_ms_median,"
      "cpu_ms_p90,cpu_ms_per_60hz,cpu_ms_per_sim_s,bullet_over_drape_cpu,wall_ms_median,wall_ms_p90,"
      "bullet_over_drape_wall,stretch_p99_pct,stretch_max_pct,pen_p99_mm,pen_max_mm,deeper_2mm_pct,"
      "inside_mean,sdf_voxel_m,in_body_pct,openings_off_pct\n",
      f.get());
  for (const PeerResult& p : peers) {
    const double bullet_cpu = median(p.bullet.cpu_ms), bullet_wall = median(p.bullet.ms);
    for (int side = 0; side < 2; ++side) {
      const PeerSide& s = side == 0 ? p.bullet : p.drape;
      const double cpu = median(s.cpu_ms);
      std::fprintf(
          f.get(),
          "%s,%s,%s,%s,%.4g,%u,%d,%d,%zu,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,%.5g,"
          "%.5g,%.4g\n",
          side == 0 ? "bullet" : "drape", side == 0 ? csvText(p.label).c_str() : csvText(p.driver.label).c_str(),
          csvText(p.driver.label).c_str(), csvText(p.take).c_str(), p.rate_hz, p.particles,
          side == 0 ? p.substeps_per_60hz : 0, side == 0 ? p.iterations : 0, s.cpu_ms.size(), cpu,
          percentile(s.cpu_ms, 90.0), cpu * p.rate_hz / 60.0, cpu * p.rate_hz, bullet_cpu / median(p.drape.cpu_ms),
          median(s.ms), percentile(s.ms, 90.0), bullet_wall / median(p.drape.ms), 100.0 * s.stretch_p99,
          100.0 * s.stretch_max, s.penetration_p99_mm, s.penetration_max_mm, 100.0 * s.deeper_than_2mm, s.inside_mean,
          side == 0 ? p.sdf_voxel_m : 0.0, 100.0 * s.in_body, 100.0 * s.openings_off);
    }
  }
  if (std::ferror(f.get())) {
    error = "error writing " + path;
    return false;
  }
  return true;
}

}  // namespace bench
