#include "stats.h"

#include "json_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

namespace replay {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The paper's reported body-stage time (rings + mesh per frame), shown for reference only: its
// hardware and mesh resolution differ from ours.
constexpr double kPaperBodyMs = 0.78;
// The paper's Table 1 at 2 000 particles (../shared/ANCHORS.md): 41.1 ms per displayed frame on a
// 2016 GPU, of which collision 36.4 and integration 3.9 (the remaining ~0.8 ms is the body stage).
constexpr double kPaperFrameMs = 41.1;
constexpr double kPaperCollideMs = 36.4;
constexpr double kPaperIntegrateMs = 3.9;
constexpr double kPaperClothMs = kPaperCollideMs + kPaperIntegrateMs;

double mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double sum = 0.0;
  for (double x : v) sum += x;
  return sum / static_cast<double>(v.size());
}

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void appendf(std::string& out, const char* fmt, ...) {
  char line[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  out += line;
}

std::string fmtMs(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t n = v.size(), mid = n / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (n % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return kNaN;
  // Nearest rank: the smallest value with at least p % of the sample at or below it.
  size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  rank = std::min(std::max<size_t>(rank, 1), v.size());
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rank - 1), v.end());
  return v[rank - 1];
}

double maximum(const std::vector<double>& v) {
  return v.empty() ? kNaN : *std::max_element(v.begin(), v.end());
}

const char* formatName(int32_t format) {
  switch (format) {
    case DRAPE_RECORDING_KINECT_CSV: return "kinect_csv";
    case DRAPE_RECORDING_BVH: return "bvh";
    case DRAPE_RECORDING_DRAPE: return "drape";
    default: return "unknown";
  }
}

const char* layoutName(int32_t layout) {
  switch (layout) {
    case DRAPE_LAYOUT_KINECT1: return "kinect1";
    case DRAPE_LAYOUT_KINECT2: return "kinect2";
    case DRAPE_LAYOUT_AZURE: return "azure";
    default: return "auto";
  }
}

std::string statsJson(const ReplayStats& s) {
  JsonWriter w;
  w.beginObject();
  w.key("drape_version").value(s.drape_version);
  w.key("recording").value(s.recording);
  w.key("format").value(formatName(s.format));
  w.key("layout").value(layoutName(s.layout));
  w.key("frames").value(s.frames);
  w.key("rejected_frames").value(s.rejected_frames);
  w.key("teleports").value(s.teleports);
  w.key("pose_jumps").value(s.pose_jumps);
  w.key("nonfinite").value(static_cast<int64_t>(s.nonfinite));
  w.key("backend").value(s.backend);
  if (s.device.empty()) w.key("device").null();
  else w.key("device").value(s.device);
  if (s.backend_fallback.empty()) w.key("backend_fallback").null();
  else w.key("backend_fallback").value(s.backend_fallback);

  w.key("ms_per_frame").beginObject();
  w.key("median").value(median(s.ms_per_frame));
  w.key("p90").value(percentile(s.ms_per_frame, 90.0));
  w.key("max").value(maximum(s.ms_per_frame));
  w.endObject();

  w.key("stages_ms").beginObject();
  w.key("skeleton").value(median(s.skeleton_ms));
  w.key("body").value(median(s.body_ms));
  w.key("proxies").value(median(s.proxies_ms));
  w.key("cloth").value(median(s.cloth_ms));
  w.key("integrate").value(median(s.integrate_ms));
  w.key("collide").value(median(s.collide_ms));
  w.key("frame").value(median(s.ms_per_frame));
  if (s.backend == "opencl") {
    // Where the device frame went (the queue's profiling events): what integrate holds beyond
    // these is the host enqueueing the launches and waiting for them.
    w.key("device").beginObject();
    w.key("upload").value(median(s.device_upload_ms));
    w.key("kernel").value(median(s.device_kernel_ms));
    w.key("readback").value(median(s.device_readback_ms));
    w.key("host").value(median(s.device_host_ms));
    w.endObject();
  }
  w.endObject();

  w.key("body").beginObject();
  w.key("vertices").value(s.vertices);
  w.key("triangles").value(s.triangles);
  w.key("watertight_frames").value(s.watertight_frames);
  w.key("volume_l").value(median(s.volume_l));
  w.key("arm_clearance_m");
  if (s.arm_clearance_m >= 0.0) w.value(s.arm_clearance_m);
  else w.value("off");
  w.endObject();

  // fit_p95_mm: per measured frame the larger of the two directions' P95 (body sticking out of
  // the ellipsoids, ellipsoids sticking out of the body), median over frames; fit_max_mm: the
  // largest single distance seen on any measured frame.
  std::vector<double> fit_p95;
  for (size_t i = 0; i < s.body_to_proxy_p95.size(); ++i)
    fit_p95.push_back(std::max(s.body_to_proxy_p95[i], s.proxy_to_body_p95[i]));
  w.key("proxies").beginObject();
  w.key("count").value(s.proxy_count);
  w.key("rule").value(s.proxy_rule == DRAPE_PROXY_RULE_PAPER ? "paper" : "drape");
  w.key("frames_measured").value(static_cast<uint32_t>(fit_p95.size()));
  w.key("fit_p95_mm").value(median(fit_p95));
  w.key("fit_max_mm").value(maximum(s.fit_max));
  w.key("body_to_proxy_p95_mm").value(median(s.body_to_proxy_p95));
  w.key("proxy_to_body_p95_mm").value(median(s.proxy_to_body_p95));
  w.key("outside_fraction").value(median(s.outside_fraction));
  w.endObject();

  w.key("shape").beginObject();
  w.key("height_m").value(static_cast<double>(s.shape.height_m));
  w.key("weight_kg").value(static_cast<double>(s.shape.weight_kg));
  w.key("neck_mm").value(static_cast<double>(s.shape.neck_mm));
  w.key("chest_mm").value(static_cast<double>(s.shape.chest_mm));
  w.key("waist_mm").value(static_cast<double>(s.shape.waist_mm));
  w.key("hip_mm").value(static_cast<double>(s.shape.hip_mm));
  w.key("thigh_mm").value(static_cast<double>(s.shape.thigh_mm));
  w.key("calf_mm").value(static_cast<double>(s.shape.calf_mm));
  w.key("upper_arm_mm").value(static_cast<double>(s.shape.upper_arm_mm));
  w.key("forearm_mm").value(static_cast<double>(s.shape.forearm_mm));
  w.endObject();

  w.key("ring_points").value(s.ring_points);

  w.key("particles").value(s.particles);
  w.key("garment").beginObject();
  if (s.has_garment) {
    w.key("kind").value(s.garment_kind);
    w.key("source").value(s.garment_from_obj ? "obj" : "template");
    w.key("solver").value(s.solver == DRAPE_SOLVER_MASS_SPRING ? "massspring" : "xpbd");
    w.key("substep_hz").value(s.substep_hz);
    if (s.solver == DRAPE_SOLVER_MASS_SPRING) {
      w.key("iterations").null();
      w.key("strain_limit").null();
      w.key("strain_limit_passes").null();
      w.key("collision_stride").null();
    } else {
      w.key("iterations").value(s.iterations);
      w.key("strain_limit").value(s.strain_limit);
      w.key("strain_limit_passes").value(static_cast<int64_t>(s.strain_limit_passes));
      w.key("collision_stride").value(s.collision_stride);
    }
  } else {
    w.key("kind").value("none");
    w.key("source").value("none");
    w.key("solver").null();
    w.key("substep_hz").null();
    w.key("iterations").null();
    w.key("strain_limit").null();
    w.key("strain_limit_passes").null();
    w.key("collision_stride").null();
  }
  w.key("triangles").value(s.garment_triangles);
  w.key("edges").value(static_cast<int64_t>(s.stretch.edgeCount()));
  w.key("attached").value(s.attached);
  w.key("fit").value(s.garment_fit == DRAPE_GARMENT_FIT_SKELETON ? "skeleton" : "shape");
  w.key("fit_by_kind").value(s.garment_fit_by_kind);
  w.key("refits").value(s.refits);
  w.key("frames_stepped").value(static_cast<uint32_t>(s.cloth_ms.size()));
  w.key("max_stretch").value(s.stretch.max());
  w.key("p99_stretch").value(s.stretch.percentile(99.0));
  w.key("body_surface_stretch").beginObject();
  w.key("from_frame").value(s.body_stretch_from_frame);
  w.key("edges").value(static_cast<int64_t>(s.body_stretch.edgeCount()));
  w.key("p99").value(s.body_stretch.percentile(99.0));
  w.key("max").value(s.body_stretch.max());
  w.key("over_5pct").value(s.body_stretch.fractionAbove(0.05));
  w.key("tubes").beginObject();
  w.key("edges").value(static_cast<int64_t>(s.body_tube_stretch.edgeCount()));
  w.key("p99").value(s.body_tube_stretch.percentile(99.0));
  w.key("over_5pct").value(s.body_tube_stretch.fractionAbove(0.05));
  w.endObject();
  w.endObject();
  w.key("proxy_inside").value(static_cast<int64_t>(s.proxy_inside));
  w.key("body_penetration_mm").beginObject();
  w.key("p99").value(maximum(s.penetration_p99_mm));
  w.key("max").value(maximum(s.penetration_max_mm));
  w.endObject();
  w.key("deeper_than_2mm").value(mean(s.deeper_than_2mm));
  w.key("inside_body").value(mean(s.inside_body));
  w.key("openings").beginObject();
  w.key("tracked").value(s.openings);
  w.key("off_frames").value(s.openings_off_frames);
  w.key("off_max").value(s.openings_off_max);
  w.endObject();
  w.key("frames_measured").value(static_cast<uint32_t>(s.penetration_p99_mm.size()));
  w.key("teleport_resets").value(s.teleport_resets);
  w.key("nan_resets").value(s.nan_resets);
  w.key("contacts").value(median(s.contacts));
  w.key("substeps").value(median(s.substeps));
  // --under: the garment worn under this one (null without it).
  w.key("under");
  if (s.has_under) {
    w.beginObject();
    w.key("kind").value(s.under_kind);
    w.key("particles").value(s.under_particles);
    w.key("crossing").beginObject();
    w.key("frames").value(s.layer_crossing.frames);
    w.key("over").value(static_cast<int64_t>(s.layer_crossing.over));
    w.key("under_share").value(s.layer_crossing.underShare());
    w.endObject();
    w.endObject();
  } else {
    w.null();
  }
  w.endObject();

  // What the adaptive pipeline skipped: ellipsoids built per frame (median) of those available,
  // stage runs skipped and steps in which every garment slept, over the whole replay.
  w.key("skipped").beginObject();
  w.key("full_pipeline").value(s.full_pipeline);
  w.key("proxies_built").value(median(s.proxies_built));
  w.key("proxies_available").value(s.proxies_available);
  w.key("stages_skipped").value(static_cast<int64_t>(s.stages_skipped));
  w.key("frames_slept").value(static_cast<int64_t>(s.frames_slept));
  w.endObject();

  const RenderStats& r = s.render;
  auto pathOrNull = [&](const char* key, const std::string& path) {
    if (path.empty()) w.key(key).null();
    else w.key(key).value(path);
  };
  w.key("render").beginObject();
  w.key("frames_rendered").value(r.frames_rendered);
  w.key("every").value(r.every);
  w.key("camera").value(r.camera);
  w.key("width").value(r.width);
  w.key("height").value(r.height);
  pathOrNull("contact_sheet", r.contact_sheet);
  pathOrNull("gif", r.gif);
  pathOrNull("mp4", r.mp4);
  w.key("ms_per_frame_median").value(median(r.ms));
  w.endObject();

  w.endObject();
  return w.str();
}

namespace {
// The summary's `fit` line: what the garment is cut for, and why.
std::string fitText(const ReplayStats& s) {
  const bool skeleton = s.garment_fit == DRAPE_GARMENT_FIT_SKELETON;
  std::string text = skeleton ? "the person's skeleton (from the first frame, or once calibrated)"
                              : "the body shape's standard proportions";
  const bool limbs = s.garment_kind == "trousers" || s.garment_kind == "longsleeve";
  if (s.garment_fit_by_kind && !skeleton) text += " (by its kind)";
  else if (s.garment_fit_by_kind) text += limbs ? " (by its kind: limbs to the wrists or ankles)" : " (by its kind: the body shape is too small for this person)";
  else if (skeleton) text += " (--garment-fit skeleton)";
  return text;
}
}  // namespace

std::string summaryText(const ReplayStats& s, const std::string& obj_dir, const std::string& stats_path) {
  std::string o;
  appendf(o, "drape-replay (Drape %s)\n", s.drape_version.c_str());
  o += "recording   " + s.recording + "\n";
  appendf(o, "            %s, %s, %u frames at %.1f Hz\n", formatName(s.format), layoutName(s.layout),
      s.recording_frames, static_cast<double>(s.recording_rate_hz));
  appendf(o, "frames      %u replayed, %u rejected, %u teleports, %llu non-finite outputs\n", s.frames,
      s.rejected_frames, s.teleports, static_cast<unsigned long long>(s.nonfinite));
  appendf(o, "body        %u vertices, %u triangles (ring_points %u), watertight %u/%u frames\n", s.vertices,
      s.triangles, s.ring_points, s.watertight_frames, s.frames - s.rejected_frames);
  appendf(o, "volume      %.2f L median (shape %.2f m, %.1f kg)\n", median(s.volume_l),
      static_cast<double>(s.shape.height_m), static_cast<double>(s.shape.weight_kg));
  if (!s.body_to_proxy_p95.empty())
    appendf(o, "proxies     %u ellipsoids (%s rule); fit P95 body->proxy %.1f mm, proxy->body %.1f mm (median of %zu frames)\n",
        s.proxy_count, s.proxy_rule == DRAPE_PROXY_RULE_PAPER ? "paper" : "drape", median(s.body_to_proxy_p95),
        median(s.proxy_to_body_p95), s.body_to_proxy_p95.size());
  if (s.has_garment) {
    const std::string passes = s.solver != DRAPE_SOLVER_MASS_SPRING && s.iterations > 1
                                   ? " x " + std::to_string(s.iterations) + " passes"
                                   : std::string();
    appendf(o, "garment     %s (%s), %s solver at %.0f Hz%s, %u particles (%u attached), %u triangles\n",
        s.garment_kind.c_str(), s.garment_from_obj ? "OBJ" : "template",
        s.solver == DRAPE_SOLVER_MASS_SPRING ? "massspring" : "xpbd", s.substep_hz, passes.c_str(), s.particles,
        s.attached, s.garment_triangles);
    appendf(o, "fit         %s%s\n",
            fitText(s).c_str(),
            s.garment_fit != DRAPE_GARMENT_FIT_SKELETON ? ""
            : s.refits > 0 ? (", cut again " + std::to_string(s.refits) + "x").c_str()
                           : ", no refit (proportions within 1 cm of the standard ones, or not calibrated)");
    appendf(o, "backend     %s%s%s%s\n", s.backend.c_str(), s.device.empty() ? "" : (" on " + s.device).c_str(),
        s.backend_fallback.empty() ? "" : " (OpenCL not used: ", s.backend_fallback.empty() ? "" : (s.backend_fallback + ")").c_str());
    appendf(o, "stretch     max %.2f %%, P99 %.2f %% (%zu edges x %zu frames pooled)\n", 100.0 * s.stretch.max(),
        100.0 * s.stretch.percentile(99.0), s.stretch.edgeCount(), s.cloth_ms.size());
    if (s.body_stretch.edgeCount() > 0)
      appendf(o, "            the body's own surface under it, against frame %u: P99 %.2f %%, %.2f %% of "
                 "samples over 5 %% (%zu edges); its tubes without the stitches: P99 %.2f %%, %.2f %% over 5 %%\n",
          s.body_stretch_from_frame, 100.0 * s.body_stretch.percentile(99.0), 100.0 * s.body_stretch.fractionAbove(0.05),
          s.body_stretch.edgeCount(), 100.0 * s.body_tube_stretch.percentile(99.0),
          100.0 * s.body_tube_stretch.fractionAbove(0.05));
    if (!s.penetration_p99_mm.empty())
      appendf(o, "inside      %llu particle-frames inside an ellipsoid; body penetration P99 %.2f mm (worst frame), "
                 "max %.2f mm; %.3f %% deeper than 2 mm, %.3f %% inside it at any depth (means of %zu measured "
                 "frames)\n",
          static_cast<unsigned long long>(s.proxy_inside), maximum(s.penetration_p99_mm),
          maximum(s.penetration_max_mm), 100.0 * mean(s.deeper_than_2mm), 100.0 * mean(s.inside_body),
          s.penetration_p99_mm.size());
    if (!s.penetration_p99_mm.empty())
      appendf(o, "openings    %u round a body part when dressed; one or more off it in %u of %zu measured frames "
                 "(at most %u at once)\n",
          s.openings, s.openings_off_frames, s.penetration_p99_mm.size(), s.openings_off_max);
    appendf(o, "cloth       %.0f contacts, %.0f substeps per frame (median); %u teleport resets, %u NaN resets\n",
        median(s.contacts), median(s.substeps), s.teleport_resets, s.nan_resets);
    if (s.has_under)
      appendf(o, "under       %s (template, layer 1; the garment layer 2), %u particles; of the garment's vertices over "
                 "it, %.2f %% lie under it (%llu vertex-frames, %u measured frames)\n",
          s.under_kind.c_str(), s.under_particles, 100.0 * s.layer_crossing.underShare(),
          static_cast<unsigned long long>(s.layer_crossing.over), s.layer_crossing.frames);
  } else {
    o += "garment     none\n";
  }
  o += "\n";
  // The paper's Table 1 (2 000 particles, K = 20, a 2016 GPU; ../shared/ANCHORS.md) for reference.
  auto row = [&](const char* name, const std::vector<double>& v, const std::string& paper) {
    appendf(o, "%-16s %10s %10s %10s %12s\n", name, fmtMs(median(v)).c_str(), fmtMs(percentile(v, 90)).c_str(),
        fmtMs(maximum(v)).c_str(), paper.c_str());
  };
  appendf(o, "%-16s %10s %10s %10s %12s\n", "stage", "median ms", "p90 ms", "max ms", "paper ms");
  row("skeleton", s.skeleton_ms, "-");
  row("body", s.body_ms, fmtMs(kPaperBodyMs));
  row("proxies", s.proxies_ms, "~0");
  if (s.has_garment) {
    row("cloth", s.cloth_ms, fmtMs(kPaperClothMs));
    row("  integrate", s.integrate_ms, fmtMs(kPaperIntegrateMs));
    row("  collide", s.collide_ms, fmtMs(kPaperCollideMs));
    if (s.backend == "opencl") {
      row("    kernels", s.device_kernel_ms, "-");
      row("    uploads", s.device_upload_ms, "-");
      row("    readback", s.device_readback_ms, "-");
      row("    host packing", s.device_host_ms, "-");
    }
    row("push+step", s.ms_per_frame, fmtMs(kPaperFrameMs));
    o += "(paper: Table 1, 2 000 particles, 20 points per ring, a 2016 GPU, per displayed frame)\n";
    if (!s.collide_ms.empty() && maximum(s.collide_ms) == 0.0 && maximum(s.cloth_ms) > 0.0)
      o += "(collide 0: this solver does not time its collision separately; integrate includes it)\n";
    if (s.backend == "opencl")
      o += "(kernels .. host packing: the device frame's split from the OpenCL queue's profiling events; integrate\n"
           " beyond their sum is the host enqueueing the launches and waiting for them)\n";
  } else {
    row("push+update", s.ms_per_frame, "-");
  }
  o += "\n";
  if (!obj_dir.empty())
    o += "obj         " + obj_dir + "/body_NNNNN.obj" + (s.has_garment ? ", garment_NNNNN.obj" : "") +
         (s.has_under ? ", under_NNNNN.obj" : "") + "\n";
  const RenderStats& r = s.render;
  if (!r.png_available && r.every != 0) {
    o += "pictures    none: this drape-replay was built without stb_image_write (install libstb-dev,\n"
         "            e.g. bash .ci/install-deps.sh, then rebuild)\n";
  } else if (r.every == 0) {
    o += "pictures    off (--no-render, --render-every 0, or --no-obj without --out)\n";
  } else {
    const std::string views = r.camera == "both" ? "sensor + side views" : r.camera + " view";
    appendf(o, "pictures    %u frames (every %u), %s, %ux%u each: %s/render_NNNNN.png\n", r.frames_rendered, r.every,
        views.c_str(), r.width, r.height, r.dir.c_str());
    if (!r.contact_sheet.empty()) o += "            contact sheet " + r.contact_sheet + "\n";
    o += "            animation " + (r.gif.empty() ? std::string("none (built without giflib: install libgif-dev)") : r.gif) +
         (r.mp4.empty() ? "; no MP4 (" + r.mp4_note + ")" : ", " + r.mp4) + "\n";
    appendf(o, "            %.1f ms per picture (median; software rasteriser, outside the timed calls)\n", median(r.ms));
  }
  if (!stats_path.empty()) o += "stats       " + stats_path + "\n";
  return o;
}

}  // namespace replay
