#include "scenario.h"

#include "metrics.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>

namespace bench {

namespace {

struct ContextDeleter {
  void operator()(drape_context* c) const { drape_context_destroy(c); }
};
struct RecordingDeleter {
  void operator()(drape_recording* r) const { drape_recording_destroy(r); }
};

}  // namespace

std::string libraryError(const char* call, drape_result r) {
  const char* msg = drape_last_error();
  return std::string(call) + " failed: " + drape_result_name(r) + (msg && *msg ? std::string(": ") + msg : "");
}

drape_skeleton_frame skeletonFrame(const Take& take, size_t i) {
  drape_skeleton_frame f{};
  f.struct_size = sizeof f;
  f.layout = take.layout;
  f.joint_count = take.joint_count;
  f.timestamp_s = take.timestamps_s[i];
  f.joints = take.frames[i].data();
  return f;
}

float frameDt(const Take& take, size_t i) {
  const double dt = i == 0 ? 1.0 / take.rate_hz : take.timestamps_s[i] - take.timestamps_s[i - 1];
  return static_cast<float>(std::min(std::max(dt, 1e-4), 1.0));
}

bool failed(const char* call, drape_result r, std::string& error) {
  error = libraryError(call, r);
  return false;
}

bool ok(const char* call, drape_result r, std::string& error) { return r == DRAPE_OK || failed(call, r, error); }

bool loadTake(const std::string& path, uint32_t frames, uint32_t stride, Take& out, std::string& error) {
  drape_recording* raw = nullptr;
  if (drape_result r = drape_recording_open(path.c_str(), DRAPE_LAYOUT_AUTO, &raw)) {
    error = libraryError(("drape_recording_open(" + path + ")").c_str(), r);
    return false;
  }
  std::unique_ptr<drape_recording, RecordingDeleter> rec(raw);
  drape_recording_info info{};
  info.struct_size = sizeof info;
  if (drape_result r = drape_recording_get_info(rec.get(), &info)) {
    error = libraryError("drape_recording_get_info", r);
    return false;
  }
  Take t;
  t.path = path;
  t.name = std::filesystem::path(path).stem().string();
  t.layout = info.layout;
  t.joint_count = info.joint_count;
  stride = std::max<uint32_t>(stride, 1);
  for (uint32_t i = 0; i < info.frame_count && (frames == 0 || t.frames.size() < frames); i += stride) {
    std::vector<drape_joint> joints(info.joint_count);
    double ts = 0.0;
    if (drape_result r = drape_recording_read_frame(rec.get(), i, joints.data(), info.joint_count, &ts)) {
      error = libraryError("drape_recording_read_frame", r);
      return false;
    }
    t.frames.push_back(std::move(joints));
    t.timestamps_s.push_back(ts);
  }
  if (t.frames.size() < 3) {
    error = "recording '" + path + "' has fewer than 3 frames to replay";
    return false;
  }
  std::vector<double> dts;
  for (size_t i = 1; i < t.timestamps_s.size(); ++i) dts.push_back(t.timestamps_s[i] - t.timestamps_s[i - 1]);
  const double dt = median(dts);
  t.rate_hz = dt > 0.0 ? 1.0 / dt : 30.0;
  out = std::move(t);
  return true;
}

std::string Setting::key() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "s%d hz%g it%u K%u rule%d resp%d ccd%u sl%g x%u n%u %s", solver, substep_hz,
                iterations, ring_points, proxy_rule, contact_response, continuous_collision, strain_limit,
                strain_limit_passes, particles, backend.c_str());
  return buf;
}

std::string Setting::modelKey() const {
  char buf[128];
  std::snprintf(buf, sizeof buf, "s%d K%u rule%d resp%d ccd%u n%u", solver, ring_points, proxy_rule, contact_response,
                continuous_collision, particles);
  return buf;
}

Setting Setting::convergedReference(bool quick) const {
  Setting base = *this;
  base.substep_hz = solver == DRAPE_SOLVER_MASS_SPRING ? kMassSpringSubstepHz : Setting{}.substep_hz;
  base.iterations = 1;
  base.strain_limit = Setting{}.strain_limit;
  base.strain_limit_passes = Setting{}.strain_limit_passes;
  return base.reference(quick);
}

Setting Setting::reference(bool quick) const {
  Setting r = *this;
  r.sweep = "reference";
  r.label = "reference";
  r.is_default = false;
  // quick: the mass-spring point runs at 2 880 Hz already, so its reference doubles the rate.
  const float rate_factor = !quick ? 16.0f : solver == DRAPE_SOLVER_XPBD ? 4.0f : 2.0f;
  r.substep_hz = std::min(rate_factor * substep_hz, 20000.0f);
  if (solver == DRAPE_SOLVER_XPBD) r.iterations = std::min<uint32_t>((quick ? 2u : 4u) * iterations, 64);
  // The backends compute the same step (within float rounding): one CPU reference serves all.
  r.backend = "cpu";
  return r;
}

bool templateTargetFor(uint32_t wanted, uint32_t& target, std::string& error) {
  drape_context* raw = nullptr;
  if (drape_result r = drape_context_create(nullptr, &raw)) return failed("drape_context_create", r, error);
  std::unique_ptr<drape_context, ContextDeleter> ctx(raw);
  uint32_t t = wanted, best = wanted, best_gap = UINT32_MAX;
  for (int attempt = 0; attempt < 4; ++attempt) {
    drape_garment_template tmpl;
    drape_garment_template_init(&tmpl);
    tmpl.particles = t;
    drape_garment* g = nullptr;
    if (drape_result r = drape_context_add_garment_template(ctx.get(), nullptr, &tmpl, nullptr, &g))
      return failed("drape_context_add_garment_template", r, error);
    uint32_t nv = 0, ni = 0;
    const drape_result size_r = drape_garment_get_mesh_size(g, &nv, &ni);
    drape_garment_destroy(g);
    if (size_r != DRAPE_OK) return failed("drape_garment_get_mesh_size", size_r, error);
    const uint32_t gap = nv > wanted ? nv - wanted : wanted - nv;
    if (gap < best_gap) {
      best_gap = gap;
      best = t;
    }
    if (gap == 0 || nv == 0) break;
    t = static_cast<uint32_t>(std::lround(static_cast<double>(t) * wanted / nv));
  }
  target = best;
  return true;
}

bool runDrape(const Take& take, const Setting& s, const RunOptions& o, RunResult& out, std::string& error) {
  using Clock = std::chrono::steady_clock;
  out = RunResult{};
  drape_context_desc desc;
  drape_context_desc_init(&desc);
  desc.ring_points = s.ring_points;
  desc.proxy_rule = s.proxy_rule;
  drape_context* raw = nullptr;
  if (drape_result r = drape_context_create(&desc, &raw)) {
    error = libraryError("drape_context_create", r);
    return false;
  }
  std::unique_ptr<drape_context, ContextDeleter> ctx(raw);
  if (s.backend == "opencl") {
    drape_backend_desc bd;
    drape_backend_desc_init(&bd);
    bd.backend = DRAPE_BACKEND_OPENCL;
    if (drape_result r = drape_context_set_backend(ctx.get(), &bd))
      return failed("drape_context_set_backend", r, error);
  } else if (s.backend != "cpu") {
    error = "unknown backend '" + s.backend + "'";
    return false;
  }
  drape_garment_desc gdesc;
  drape_garment_desc_init(&gdesc);
  gdesc.solver = s.solver;
  drape_cloth_params cloth;
  drape_cloth_params_init(&cloth);
  cloth.substep_hz = s.substep_hz;
  cloth.iterations = s.iterations;
  cloth.contact_response = s.contact_response;
  cloth.continuous_collision = s.continuous_collision;
  cloth.strain_limit = s.strain_limit;
  cloth.strain_limit_passes = s.strain_limit_passes;
  // Room for a whole frame of the take at this rate (the reference runs thousands of Hz).
  const auto per_frame = static_cast<uint32_t>(std::ceil(s.substep_hz / take.rate_hz));
  cloth.max_substeps = std::max(cloth.max_substeps, std::min<uint32_t>(1000, 2 * per_frame));
  drape_garment_template tmpl;
  drape_garment_template_init(&tmpl);
  tmpl.kind = DRAPE_GARMENT_TSHIRT;
  tmpl.particles = s.particles;
  drape_garment* garment = nullptr;
  if (drape_result r = drape_context_add_garment_template(ctx.get(), &gdesc, &tmpl, &cloth, &garment)) {
    error = libraryError("drape_context_add_garment_template", r);
    return false;
  }
  if (s.backend == "opencl") {
    // Asking for OpenCL falls back to the CPU when no device works: a CPU run must not be
    // reported as an OpenCL one.
    drape_backend_info bi{};
    bi.struct_size = sizeof bi;
    if (drape_result r = drape_context_get_backend_info(ctx.get(), &bi))
      return failed("drape_context_get_backend_info", r, error);
    if (bi.active != DRAPE_BACKEND_OPENCL || bi.opencl_garments != 1) {
      error =
          std::string("OpenCL is not in use (") + (bi.fallback_reason ? bi.fallback_reason : "no reason given") + ")";
      return false;
    }
    out.device =
        std::string(bi.device_name ? bi.device_name : "") + " (" + (bi.platform_name ? bi.platform_name : "") + ")";
  }
  uint32_t nv = 0, ni = 0;
  if (drape_result r = drape_garment_get_mesh_size(garment, &nv, &ni)) {
    error = libraryError("drape_garment_get_mesh_size", r);
    return false;
  }
  out.particles = nv;
  out.indices.resize(ni);
  out.rest.resize(nv);
  uint32_t body_nv = 0, body_ni = 0;
  if (!ok("drape_garment_read_mesh", drape_garment_read_mesh(garment, nullptr, nullptr, 0, out.indices.data(), ni),
          error) ||
      !ok("drape_garment_read_rest_positions", drape_garment_read_rest_positions(garment, out.rest.data(), nv),
          error) ||
      !ok("drape_context_get_body_mesh_size", drape_context_get_body_mesh_size(ctx.get(), &body_nv, &body_ni), error))
    return false;
  std::vector<drape_vec3> body(body_nv);
  std::vector<uint32_t> body_idx(body_ni);
  if (!ok("drape_context_read_body_mesh",
          drape_context_read_body_mesh(ctx.get(), nullptr, nullptr, 0, body_idx.data(), body_ni), error))
    return false;

  BodySurface surface;
  PenetrationMeter pen;
  StretchMeter stretch;
  stretch.setMesh(out.indices, out.rest);
  std::vector<drape_vec3> x(nv);
  std::vector<double> inside, substeps;
  size_t openings_off_frames = 0;  // of the measured frames (one `inside` entry each)
  uint32_t refits = 0;
  for (size_t i = 0; i < take.frames.size(); ++i) {
    const drape_skeleton_frame f = skeletonFrame(take, i);
    const Clock::time_point t0 = Clock::now();
    if (drape_result r = drape_context_push_skeleton(ctx.get(), &f)) {
      error = libraryError("drape_context_push_skeleton", r);
      return false;
    }
    if (drape_result r = drape_context_step(ctx.get(), frameDt(take, i))) {
      error = libraryError("drape_context_step", r);
      return false;
    }
    const double frame_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    drape_frame_stats fs{};
    fs.struct_size = sizeof fs;
    drape_garment_stats gs{};
    gs.struct_size = sizeof gs;
    if (!ok("drape_context_get_frame_stats", drape_context_get_frame_stats(ctx.get(), &fs), error) ||
        !ok("drape_garment_get_stats", drape_garment_get_stats(garment, &gs), error))
      return false;
    out.attached = gs.attached;
    out.nan_resets += gs.nan_reset;
    if (gs.refits != refits) {
      // Cut again for the person's skeleton (drape_garment_fit): stretch against the new rest shape.
      refits = gs.refits;
      if (!ok("drape_garment_read_rest_positions", drape_garment_read_rest_positions(garment, out.rest.data(), nv),
              error))
        return false;
      stretch.setRest(out.rest);
    }
    substeps.push_back(gs.substeps);
    // The first frame (pose blended in over extra frames) and teleports are not steady frames.
    if (gs.blend_frames == 0 && !gs.teleport_reset)
      out.times.push_back(
          {frame_ms, fs.skeleton_ms, fs.body_ms, fs.proxies_ms, gs.step_ms, gs.integrate_ms, gs.collide_ms});
    if (!o.measure && !o.keep_positions) continue;
    if (drape_result r = drape_garment_read_mesh(garment, x.data(), nullptr, nv, nullptr, 0)) {
      error = libraryError("drape_garment_read_mesh", r);
      return false;
    }
    if (o.keep_positions) out.positions.push_back(x);
    if (!o.measure) continue;
    if (out.pinned.empty()) {  // attached particles: w = 0 in the borrowed view
      const float* xyzw = nullptr;
      uint32_t n = 0;
      if (!ok("drape_garment_view_positions", drape_garment_view_positions(garment, &xyzw, &n), error)) return false;
      out.pinned.assign(nv, 0);
      for (uint32_t k = 0; k < n && k < nv; ++k) out.pinned[k] = xyzw[4 * k + 3] == 0.0f;
    }
    drape_garment_accuracy acc{};
    acc.struct_size = sizeof acc;
    if (!ok("drape_garment_measure", drape_garment_measure(garment, &acc), error) ||
        !ok("drape_context_read_body_mesh",
            drape_context_read_body_mesh(ctx.get(), body.data(), nullptr, body_nv, nullptr, 0), error))
      return false;
    inside.push_back(acc.proxy_inside);
    if (acc.openings_off > 0) ++openings_off_frames;
    out.inside_max = std::max(out.inside_max, acc.proxy_inside);
    if (!surface.set(body, body_idx)) {
      error = "the body mesh could not be measured (non-finite vertex?)";
      return false;
    }
    pen.addFrame(surface, x.data(), nv);
    stretch.addFrame(x.data());
  }
  out.substeps_per_frame = median(substeps);
  if (o.measure) {
    readErrors(stretch, pen, inside, out);
    out.openings_off = inside.empty() ? 0.0 : static_cast<double>(openings_off_frames) / static_cast<double>(inside.size());
  }
  return true;
}

}  // namespace bench
