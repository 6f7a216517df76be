#include "report.h"

#include "metrics.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

namespace bench {

namespace {

// The paper's Table 1 at 2 000 particles, K = 20 (a 2016 GPU, per displayed frame; ANCHORS.md).
constexpr double kPaperFrameMs = 41.1, kPaperCollideMs = 36.4, kPaperIntegrateMs = 3.9, kPaperBodyMs = 0.78;
// NvCloth 1.1.6 CPU, 2 016 particles, 300 Hz, tethers on: 0.39 ms per 1/60 s (ANCHORS.md).
constexpr double kNvClothMsPer60Hz = 0.39;
// Its accuracy there (ANCHORS.md): 0.40 % of the particles inside the body, P99 stretch 25 %.
constexpr double kNvClothInsideBody = 0.004;
constexpr double kNvClothStretchP99 = 0.25;
// Bullet 4 x 10 on this kind of machine (ANCHORS.md): 36 ms per 1/60 s.
constexpr double kBulletAnchorMsPer60Hz = 36.0;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void appendf(std::string& o, const char* fmt, ...) {
  char line[1024];
  va_list a;
  va_start(a, fmt);
  std::vsnprintf(line, sizeof line, fmt, a);
  va_end(a);
  o += line;
}

std::string firstLineWith(const char* path, const std::string& prefix) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(prefix, 0) == 0) return line.substr(prefix.size());
  return "";
}

const Row* defaultRow(const ReportInput& in, const std::string& take) {
  for (const auto& rs : in.rows)
    for (const Row& r : rs)
      if (r.take == take && r.setting.is_default) return &r;
  return nullptr;
}

// The converged reference that prices row `r`: the one of its take and model (Setting::modelKey).
const Row* referenceFor(const ReportInput& in, const Row& r) {
  const std::string model = r.setting.modelKey();
  for (const Row& ref : in.references)
    if (ref.take == r.take && ref.setting.modelKey() == model) return &ref;
  return nullptr;
}

// What solver effort reaches: each converged reference's own error figures (references.csv), and
// Drape's default against its reference and against the targets that solver effort cannot buy.
void renderReferences(const ReportInput& in, std::string& o) {
  if (in.references.empty()) return;
  o += "\n## What solver effort reaches: the converged references (`references.csv`)\n\n"
       "Each reference is the same input at 16x the substeps and 4x the iterations (`--quick`: 4x and 2x), "
       "measured by the same meters as the settings (not timed). One reference serves every setting that differs "
       "from it only in substeps, iterations or strain limit; it is listed under the first setting that asked for "
       "it. What a setting's error exceeds its reference's by is the solver's convergence; what the reference "
       "itself shows belongs to the model (the garment's cut, its pins, friction, the body and its ellipsoids), "
       "and more substeps or iterations do not take it away.\n\n"
       "| converges | take | substeps per frame x iterations | stretch % P99 / max | penetration mm P99 / max | "
       "> 2 mm % | in body % | off % | inside |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : in.references)
    appendf(o, "| %s | %s | %.0f x %u | %.2f / %.1f | %.2f / %.1f | %.3f | %.3f | %.0f | %.2f |\n",
            r.setting.label.c_str(), r.take.c_str(), r.substeps_per_frame, r.setting.iterations,
            100.0 * r.stretch_p99, 100.0 * r.stretch_max, r.pen_p99_mm, r.pen_max_mm, 100.0 * r.deeper_than_2mm,
            100.0 * r.in_body, 100.0 * r.openings_off, r.inside_mean);
  for (const Take& t : in.takes) {
    const Row* d = defaultRow(in, t.name);
    const Row* ref = d ? referenceFor(in, *d) : nullptr;
    if (!d || !ref) continue;
    appendf(o,
            "\nOn `%s`, Drape's default: stretch P99 %.2f %% against its converged reference's %.2f %% (the goal, "
            "ANCHORS.md: 5 %%; %s), cloth in the body %.2f %% against %.2f %% (NvCloth: %.2f %%; %s).\n",
            t.name.c_str(), 100.0 * d->stretch_p99, 100.0 * ref->stretch_p99,
            ref->stretch_p99 > 0.05 ? "above it in the reference too" : "the reference is below it",
            100.0 * d->in_body, 100.0 * ref->in_body, 100.0 * kNvClothInsideBody,
            ref->in_body >= kNvClothInsideBody ? "not less in the reference either" : "the reference is less");
  }
}

// --peer-spread: per take and Drape setting, Bullet 4 x 10 (the peer's field) from that setting's
// shirt and from the seeds' shifted copies of it, against Drape at that setting (the same in every
// run: Drape's start is not perturbed).
void renderSpread(const ReportInput& in, std::string& o) {
  if (in.spread.empty()) return;
  appendf(o,
          "\n## Bullet 4 x 10 over several starting shirts (`--peer-spread`)\n\n"
          "Bullet's free nodes start shifted together by %.1f mm (a direction drawn per seed) from where Drape "
          "at the setting placed them; seed 0 is the run above. Drape starts as above in every run.\n\n"
          "| take | Drape setting (Bullet from its shirt) | starts | Bullet stretch %% P99: min / median / max | "
          "Bullet penetration mm P99: min / median / max | Drape: stretch %% P99, penetration mm | Drape's stretch "
          "below Bullet's |\n|---|---|---|---|---|---|---|\n",
          1000.0 * kStartShiftM);
  for (const PeerResult& head : in.peers) {
    if (head.substeps_per_60hz != 4 || head.iterations != 10 || head.sdf_voxel_m != in.peer_field_m) continue;
    std::vector<const PeerResult*> runs = {&head};
    for (const PeerResult& p : in.spread)
      if (p.take == head.take && p.driver.label == head.driver.label) runs.push_back(&p);
    if (runs.size() < 2) continue;
    std::vector<double> stretch, pen;
    int below = 0;
    for (const PeerResult* p : runs) {
      stretch.push_back(100.0 * p->bullet.stretch_p99);
      pen.push_back(p->bullet.penetration_p99_mm);
      below += head.drape.stretch_p99 < p->bullet.stretch_p99 ? 1 : 0;
    }
    appendf(o, "| %s | %s | %zu | %.2f / %.2f / %.2f | %.2f / %.2f / %.2f | %.2f, %.2f | in %d of %zu |\n",
            head.take.c_str(), head.driver.label.c_str(), runs.size(), *std::min_element(stretch.begin(), stretch.end()),
            median(stretch), *std::max_element(stretch.begin(), stretch.end()), *std::min_element(pen.begin(), pen.end()),
            median(pen), *std::max_element(pen.begin(), pen.end()), 100.0 * head.drape.stretch_p99,
            head.drape.penetration_p99_mm, below, runs.size());
  }
}

}  // namespace

std::string machineDescription() {
  std::string cpu = firstLineWith("/proc/cpuinfo", "model name\t: ");
  std::string os = firstLineWith("/etc/os-release", "PRETTY_NAME=");
  if (os.size() >= 2 && os.front() == '"') os = os.substr(1, os.size() - 2);
  std::string o = (cpu.empty() ? std::string("unknown CPU") : cpu) + ", " +
                  std::to_string(std::thread::hardware_concurrency()) + " logical CPUs visible, " +
                  (os.empty() ? std::string("unknown OS") : os);
#if defined(__VERSION__) && defined(__GNUC__) && !defined(__clang__)
  o += ", g++ " __VERSION__;
#elif defined(__VERSION__)
  o += ", " __VERSION__;
#endif
#if defined(__OPTIMIZE__)
  o += ", optimised build";
#else
  o += ", UNOPTIMISED build (timings meaningless)";
#endif
  return o + ", one thread";
}

std::string renderReport(const ReportInput& in) {
  std::string o = "# drape-bench results\n\n";
  appendf(o, "- command: `%s`\n- machine: %s\n- Drape %s\n", in.command.c_str(), machineDescription().c_str(),
          drape_version_string());
  for (const Take& t : in.takes)
    appendf(o, "- take `%s`: %zu frames replayed at %.0f Hz (%.1f s)\n", t.name.c_str(), t.frames.size(), t.rate_hz,
            static_cast<double>(t.frames.size()) / t.rate_hz);
  o += "\nTimes: median (p90) over every steady frame of every timed repeat, ms per replayed frame. Errors from "
       "one measuring run: deviation = RMS / max vertex distance to the converged reference (16x substeps, 4x "
       "iterations), averaged over frames; stretch = P99 / max over all structural edges of all frames; "
       "penetration = P99 / max depth of all garment vertices of all frames inside the body mesh; in body = share "
       "of those vertex-frames inside it at any depth; inside = "
       "particles inside an ellipsoid they collide with, mean per frame; energy = drift of the free-hanging "
       "garment as a fraction of M g H (docs/benchmarks.md).\n";
  for (size_t k = 0; k < in.sweeps.size(); ++k) {
    appendf(o, "\n## %s (`%s.csv`)\n\n", in.sweeps[k].title.c_str(), in.sweeps[k].name.c_str());
    o += "| setting | take | frame ms | cloth ms | collide ms | deviation mm RMS / max | stretch % P99 / max | "
         "penetration mm P99 / max | > 2 mm % | in body % | inside | openings off % | energy drift "
         "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : in.rows[k]) {
      char energy[32];
      std::snprintf(energy, sizeof energy, "%+.4f", r.energy.drift);
      appendf(
          o, "| %s%s | %s | %.3f (%.3f) | %.3f | %.3f | %.2f / %.1f | %.2f / %.1f | %.2f / %.1f | %.3f | %.3f | %.2f | %.0f | %s |\n",
          r.setting.label.c_str(), r.setting.is_default ? " **(default)**" : "", r.take.c_str(), r.frame.median,
          r.frame.p90, r.cloth.median, r.collide.median, r.dev_rms_mm, r.dev_max_mm, 100.0 * r.stretch_p99,
          100.0 * r.stretch_max, r.pen_p99_mm, r.pen_max_mm, 100.0 * r.deeper_than_2mm, 100.0 * r.in_body,
          r.inside_mean, 100.0 * r.openings_off, r.energy.exploded ? "exploded" : energy);
    }
    for (const Row& r : in.rows[k])
      if (!r.device.empty())
        appendf(o, "\n%s on %s: OpenCL device %s.\n", r.setting.label.c_str(), r.take.c_str(), r.device.c_str());
  }

  // The paper's Table 1 beside ours.
  for (const Row& t1 : in.table1) {
    const Row* d = &t1;
    {
      appendf(o, "\n## The paper's Table 1 beside ours (%u particles, K = %u, take `%s`)\n\n", d->particles,
              d->setting.ring_points, d->take.c_str());
      o += "| stage | Drape median ms | Drape p90 ms | paper ms (2016 GPU, per displayed frame) |\n|---|---|---|---|\n";
      appendf(o, "| skeleton | %.3f | %.3f | - |\n", d->skeleton.median, d->skeleton.p90);
      appendf(o, "| body (rings + mesh) | %.3f | %.3f | %.2f |\n", d->body.median, d->body.p90, kPaperBodyMs);
      appendf(o, "| proxies | %.3f | %.3f | ~0 |\n", d->proxies.median, d->proxies.p90);
      appendf(o, "| cloth: integration + constraints | %.3f | %.3f | %.1f |\n", d->integrate.median, d->integrate.p90,
              kPaperIntegrateMs);
      appendf(o, "| cloth: collision | %.3f | %.3f | %.1f |\n", d->collide.median, d->collide.p90, kPaperCollideMs);
      appendf(o, "| whole frame | %.3f | %.3f | %.1f |\n", d->frame.median, d->frame.p90, kPaperFrameMs);
      appendf(o, "\nOur frame is 1/%.0f s of motion at %.0f substeps; the paper's a displayed frame (~24 FPS).\n",
              d->rate_hz, d->substeps_per_frame);
    }
  }

  renderReferences(in, o);

  // The peer.
  o += "\n## Bullet soft body beside Drape, same run\n\n";
  if (in.peers.empty()) {
    o += in.peer_note.empty() ? std::string("Not run.\n") : in.peer_note + "\n";
  } else {
    o += "The same mesh, attachments, ellipsoids and frames for both. Drape runs at a setting and Bullet starts "
         "from that setting's dressed shirt (Bullet's stretch follows the shirt it starts from, docs/benchmarks.md): "
         "Bullet 4 x 10 on the peer's field once per Drape setting, the other Bullet settings from the default's "
         "shirt. Time: thread CPU time per frame, median "
         "(Bullet: its stepSimulation calls; Drape: push + its whole step, skeleton to cloth, measured beside it in "
         "the same frame); wall time of the cloth step alone in brackets. Penetration and stretch by the same meters "
         "for both; in body = vertex-frames inside the body mesh at any depth (ANCHORS.md's \"cloth inside the "
         "body\": NvCloth 0.40 %, Bullet 4 x 10 2.2 %); off = frames with an opening (hem, collar, a sleeve's "
         "cuff) off the body part it went round at the start, by one meter for both (OpeningsMeter: the "
         "library's linking test on body parts through the ellipsoids' centres); inside = free vertices inside any tracking ellipsoid (Drape's garments collide only with their "
         "own body parts' ellipsoids, so sleeve cloth resting on the torso counts here). Bullet meets the "
         "ellipsoids through a distance field sampled on a voxel grid (the setting's field); Bullet's own 0.25 m "
         "voxel is coarser than a forearm and lets the cloth sink into the body, so the peer's is finer and the "
         "target below is judged on it.\n\n";
    o +=
        "| take | engine | setting | CPU ms per frame (wall, cloth) | CPU ms per 1/60 s | Bullet / Drape (CPU; wall) | "
        "stretch % P99 / max | penetration mm P99 / max | > 2 mm % | in body % | off % | inside "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const PeerResult& p : in.peers) {
      const double b = median(p.bullet.cpu_ms), d = median(p.drape.cpu_ms);
      const double bw = median(p.bullet.ms), dw = median(p.drape.ms);
      appendf(o,
              "| %s (%.0f Hz, %u particles) | Bullet 3.24 | %s (substeps per 1/60 s x iterations) | %.2f (%.2f) | "
              "%.2f | **%.0fx**; %.0fx | %.1f / %.1f | %.1f / %.1f | %.2f | %.2f | %.0f | %.1f |\n",
              p.take.c_str(), p.rate_hz, p.particles, p.label.c_str(), b, bw, b * p.rate_hz / 60.0, b / d, bw / dw,
              100.0 * p.bullet.stretch_p99, 100.0 * p.bullet.stretch_max, p.bullet.penetration_p99_mm,
              p.bullet.penetration_max_mm, 100.0 * p.bullet.deeper_than_2mm, 100.0 * p.bullet.in_body,
              100.0 * p.bullet.openings_off, p.bullet.inside_mean);
      appendf(o, "| | Drape | %s, beside it | %.3f (%.3f) | %.3f | 1 | %.2f / %.1f | %.2f / %.1f | %.2f | %.2f | %.0f | %.2f |\n",
              p.driver.label.c_str(), d, dw, d * p.rate_hz / 60.0, 100.0 * p.drape.stretch_p99,
              100.0 * p.drape.stretch_max, p.drape.penetration_p99_mm, p.drape.penetration_max_mm,
              100.0 * p.drape.deeper_than_2mm, 100.0 * p.drape.in_body, 100.0 * p.drape.openings_off,
              p.drape.inside_mean);
    }
    // The target at each setting, against Bullet from that setting's shirt.
    for (const PeerResult& p : in.peers) {
      if (p.substeps_per_60hz != 4 || p.iterations != 10 || p.sdf_voxel_m != in.peer_field_m) continue;
      const PeerSide& d = p.drape;
      const double ratio = median(p.bullet.cpu_ms) / median(d.cpu_ms);
      const bool less_pen =
          d.penetration_p99_mm <= p.bullet.penetration_p99_mm && d.deeper_than_2mm <= p.bullet.deeper_than_2mm;
      const bool less_stretch = d.stretch_p99 < p.bullet.stretch_p99;
      const std::string setting = p.driver.isDefault() ? "Drape's default" : "Drape at " + p.driver.label;
      appendf(o,
              "\nTarget on `%s` (Drape >= 50x faster than Bullet 4 x 10, with less penetration and stretch; "
              "Bullet on its %g cm field, from the setting's shirt), %s: %.0fx faster in CPU time (%s), penetration "
              "%s, stretch %s (%.2f against %.2f %%; an opening off its body part in %.0f %% of the frames, "
              "Bullet's in %.0f %%).",
              p.take.c_str(), 100.0 * p.sdf_voxel_m, setting.c_str(), ratio, ratio >= 50.0 ? "met" : "NOT met",
              less_pen ? "less (met)" : "NOT less", less_stretch ? "less (met)" : "NOT less", 100.0 * d.stretch_p99,
              100.0 * p.bullet.stretch_p99, 100.0 * d.openings_off, 100.0 * p.bullet.openings_off);
      if (p.driver.isDefault())
        appendf(o, " Bullet 4 x 10 here: %.1f ms per 1/60 s (ANCHORS.md: %.0f ms).",
                median(p.bullet.cpu_ms) * p.rate_hz / 60.0, kBulletAnchorMsPer60Hz);
      o += "\n";
    }
  }

  renderSpread(in, o);

  // NvCloth per simulated second.
  if (!in.takes.empty()) {
    const Row* d = in.table1.empty() ? defaultRow(in, in.takes[0].name) : &in.table1[0];
    if (d) {
      const double nv = kNvClothMsPer60Hz * 60.0;
      const double cloth = d->cloth.median * d->rate_hz, frame = d->frame.median * d->rate_hz;
      o += "\n## Against NvCloth (ANCHORS.md, measured on this kind of machine, not in this run)\n\n";
      appendf(o,
              "Drape: the Table 1 run on `%s` (wall-time medians of the sweep) and the Drape side of the Bullet "
              "run (CPU time).\n\n",
              d->take.c_str());
      o += "| | ms per simulated second | vs NvCloth 1.1.6 (0.39 ms per 1/60 s = 23.4 ms/s, 2 016 particles, 300 Hz) "
           "|\n|---|---|---|\n";
      appendf(o, "| NvCloth, cloth only | %.1f | 1 |\n", nv);
      appendf(o, "| Drape default, cloth only (%u particles, take `%s`) | %.1f | %.2fx %s |\n", d->particles,
              d->take.c_str(), cloth, cloth > nv ? cloth / nv : nv / cloth, cloth > nv ? "slower" : "faster");
      appendf(o, "| Drape default, whole frame (skeleton + body + proxies + cloth) | %.1f | %.2fx %s |\n", frame,
              frame > nv ? frame / nv : nv / frame, frame > nv ? "slower" : "faster");
      for (const PeerResult& p : in.peers) {
        if (p.take != d->take || p.substeps_per_60hz != 4 || p.sdf_voxel_m != in.peer_field_m ||
            !p.driver.isDefault())
          continue;
        const double cpu = median(p.drape.cpu_ms) * p.rate_hz;
        appendf(o, "| Drape default, whole frame, thread CPU time (beside Bullet, same garment) | %.1f | %.2fx %s |\n",
                cpu, cpu > nv ? cpu / nv : nv / cpu, cpu > nv ? "slower" : "faster");
      }
      // Accuracy: Drape's by this run's meters, NvCloth's as ANCHORS.md gives it (its harness is not
      // ours: how it decided "inside" is not stated there).
      appendf(o,
              "\n| accuracy | NvCloth 1.1.6 (ANCHORS.md) | Drape default (%u particles, take `%s`) |\n|---|---|---|\n",
              d->particles, d->take.c_str());
      appendf(o, "| cloth inside the body (Drape: vertex-frames inside the body mesh at any depth) | %.2f %% | %.2f %% (%s) |\n",
              100.0 * kNvClothInsideBody, 100.0 * d->in_body, d->in_body < kNvClothInsideBody ? "less" : "NOT less");
      appendf(o, "| stretch P99 | %.0f %% | %.2f %% (%s) |\n", 100.0 * kNvClothStretchP99, 100.0 * d->stretch_p99,
              d->stretch_p99 < kNvClothStretchP99 ? "less" : "NOT less");
    }
  }
  if (!in.notes.empty()) {
    o += "\n## Notes\n\n";
    for (const std::string& n : in.notes) o += "- " + n + "\n";
  }
  return o;
}

}  // namespace bench
