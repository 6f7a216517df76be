// drape-replay: replays a skeleton recording through Drape's public C ABI (drape.h only, linked
// against the shared library like any user program), dresses the person in a garment, checks every
// body mesh (finite numbers, watertight, enclosed volume) and the garment (finite numbers, stretch,
// penetration), optionally writes body and garment OBJs per frame and writes a stats JSON.
// Usage and the stats schema: docs/replay.md.
#include <drape/drape.h>

#include "mesh_checks.h"
#include "obj_writer.h"
#include "options.h"
#include "pictures.h"
#include "progress.h"
#include "stats.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

namespace fs = std::filesystem;
using replay::Options;
using replay::ReplayStats;

#ifndef DRAPE_REPLAY_DEFAULT_RECORDING
#define DRAPE_REPLAY_DEFAULT_RECORDING ""
#endif
#ifndef DRAPE_REPLAY_INSTALLED_RECORDING
#define DRAPE_REPLAY_INSTALLED_RECORDING ""
#endif

namespace {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;
// The paper's mass-spring with explicit Euler needs ~3 kHz (drape.h): 96 substeps per 1/30 s.
constexpr float kMassSpringSubstepHz = 2880.0f;

// The one-line error on stderr (newlines in library messages are flattened).
int fail(int code, std::string message) {
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  std::fprintf(stderr, "drape-replay: error: %s\n", message.c_str());
  return code;
}

std::string libraryReason(drape_result r) {
  const char* msg = drape_last_error();
  std::string s = drape_result_name(r);
  if (msg && *msg) s += std::string(": ") + msg;
  return s;
}

// A garment's mesh as drape-replay reads it: sizes and indices once (load), positions (and the
// normals, when `normals` was asked for) every frame (read). `which` names the garment in errors.
struct GarmentMesh {
  uint32_t vertices = 0, index_count = 0;
  std::vector<drape_vec3> positions, normals;
  std::vector<uint32_t> indices;

  bool load(drape_garment* g, bool with_normals, const std::string& which, std::string& error) {
    if (drape_result r = drape_garment_get_mesh_size(g, &vertices, &index_count)) {
      error = "drape_garment_get_mesh_size" + which + " failed: " + libraryReason(r);
      return false;
    }
    positions.resize(vertices);
    if (with_normals) normals.resize(vertices);
    indices.resize(index_count);
    if (drape_result r = drape_garment_read_mesh(g, nullptr, nullptr, 0, indices.data(), index_count)) {
      error = "drape_garment_read_mesh" + which + " (indices) failed: " + libraryReason(r);
      return false;
    }
    return true;
  }
  bool read(drape_garment* g, uint32_t frame, const std::string& which, std::string& error) {
    if (drape_result r = drape_garment_read_mesh(g, positions.data(), normals.empty() ? nullptr : normals.data(),
                                                 vertices, nullptr, 0)) {
      error = "drape_garment_read_mesh" + which + " failed on frame " + std::to_string(frame) + ": " +
              libraryReason(r);
      return false;
    }
    return true;
  }
};

struct RecordingDeleter {
  void operator()(drape_recording* r) const { drape_recording_destroy(r); }
};
struct ContextDeleter {
  void operator()(drape_context* c) const { drape_context_destroy(c); }
};

// The bundled recording: beside an installed binary first (relocatable install), else the
// source-tree copy whose path the build compiled in.
std::string bundledRecording(const char* argv0) {
  const std::string installed_rel = DRAPE_REPLAY_INSTALLED_RECORDING;
  if (!installed_rel.empty()) {
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec && argv0) exe = fs::absolute(argv0, ec);
    if (!ec && !exe.empty()) {
      const fs::path candidate = (exe.parent_path() / installed_rel).lexically_normal();
      if (fs::is_regular_file(candidate, ec)) return candidate.string();
    }
  }
  return DRAPE_REPLAY_DEFAULT_RECORDING;
}

// Creates `dir` (and parents) if missing. Returns false with a message when it cannot.
bool ensureDirectory(const fs::path& dir, std::string& error) {
  if (dir.empty()) return true;
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return true;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    error = "cannot create directory '" + dir.string() + "'" + (ec ? ": " + ec.message() : std::string()) +
            "; choose a writable --out/--stats location";
    return false;
  }
  return true;
}

bool isFatalLibraryError(drape_result r) {
  return r == DRAPE_ERROR_INTERNAL || r == DRAPE_ERROR_OUT_OF_MEMORY || r == DRAPE_ERROR_INVALID_HANDLE ||
         r == DRAPE_ERROR_NULL_ARGUMENT;
}

int run(int argc, char** argv) {
  Options opt;
  std::string error;
  if (!replay::parseOptions(argc, argv, opt, error)) return fail(kExitUsage, error);
  if (opt.help) {
    std::fputs(replay::helpText().c_str(), stdout);
    return kExitOk;
  }
  if ((drape_version() >> 22) != DRAPE_VERSION_MAJOR)
    return fail(kExitFailure, std::string("the Drape library is version ") + drape_version_string() +
                                  ", this program was built for major version " +
                                  std::to_string(DRAPE_VERSION_MAJOR) + "; rebuild drape-replay");

  // Recording.
  std::string path = opt.recording;
  if (path.empty()) {
    path = bundledRecording(argc > 0 ? argv[0] : nullptr);
    if (path.empty() || !fs::exists(path))
      return fail(kExitUsage, "the bundled recording was not found (" + path +
                                  "); pass --recording PATH to a Kinect v2 CSV, BVH or .drec file");
  }
  drape_recording* raw_rec = nullptr;
  if (drape_result r = drape_recording_open(path.c_str(), opt.layout, &raw_rec)) {
    // The library's message names the file.
    if (r == DRAPE_ERROR_IO)
      return fail(kExitUsage, "cannot read the recording (" + libraryReason(r) + "); check the --recording path");
    return fail(isFatalLibraryError(r) ? kExitFailure : kExitUsage,
                "cannot parse the recording (" + libraryReason(r) +
                    "); pass a Kinect v2 CSV, BVH or .drec file, with --layout auto or the file's layout");
  }
  std::unique_ptr<drape_recording, RecordingDeleter> rec(raw_rec);
  drape_recording_info info{};
  info.struct_size = sizeof info;
  if (drape_result r = drape_recording_get_info(rec.get(), &info))
    return fail(kExitFailure, "drape_recording_get_info failed: " + libraryReason(r));
  if (info.frame_count == 0)
    return fail(kExitUsage, "recording '" + path + "' holds no frames; pass a recording with at least one frame");

  // Context and body.
  drape_context_desc desc;
  drape_context_desc_init(&desc);
  if (opt.ring_points != 0) desc.ring_points = opt.ring_points;
  desc.proxy_rule = opt.proxy_rule;
  desc.garment_fit = opt.garment_fit;
  if (opt.arms_on_bones) desc.arms_clear_torso = 0;
  if (opt.arm_clearance_m >= 0.0) desc.arm_torso_clearance_m = static_cast<float>(opt.arm_clearance_m);
  drape_context* raw_ctx = nullptr;
  if (drape_result r = drape_context_create(&desc, &raw_ctx)) {
    if (isFatalLibraryError(r)) return fail(kExitFailure, "drape_context_create failed: " + libraryReason(r));
    return fail(kExitUsage, "--ring-points " + std::to_string(desc.ring_points) + " was refused (" +
                                libraryReason(r) + "); use a multiple of 4 in [8, 256], e.g. 20");
  }
  std::unique_ptr<drape_context, ContextDeleter> ctx(raw_ctx);
  if (opt.full_pipeline) {
    drape_pipeline_options po;
    drape_pipeline_options_init(&po);
    po.cull_proxies = po.stages_on_demand = po.sleep = 0;
    if (drape_result r = drape_context_set_pipeline_options(ctx.get(), &po))
      return fail(kExitFailure, "drape_context_set_pipeline_options failed: " + libraryReason(r));
  }
  if (opt.body_given) {
    if (drape_result r = drape_context_set_body_shape(ctx.get(), &opt.shape)) {
      if (isFatalLibraryError(r)) return fail(kExitFailure, "drape_context_set_body_shape failed: " + libraryReason(r));
      return fail(kExitUsage, "--body was refused (" + libraryReason(r) +
                                  "); height_m in [0.8, 2.5], weight_kg in [15, 300], girths 0 or [50, 3000] mm");
    }
  }

  // The garment, sized to the body set above. Owned by the context (destroyed with it).
  drape_garment* garment = nullptr;
  drape_cloth_params cloth;
  drape_cloth_params_init(&cloth);
  if (!opt.garment_none) {
    drape_garment_desc gdesc;
    drape_garment_desc_init(&gdesc);
    gdesc.solver = opt.solver;
    gdesc.cut = opt.garment_cut;
    if (opt.substeps != 0) cloth.substep_hz = 30.0f * static_cast<float>(opt.substeps);
    else if (opt.solver == DRAPE_SOLVER_MASS_SPRING) cloth.substep_hz = kMassSpringSubstepHz;
    if (opt.iterations != 0) cloth.iterations = opt.iterations;
    if (opt.strain_limit >= 0.0) cloth.strain_limit = static_cast<float>(opt.strain_limit);
    if (opt.collision_stride >= 0) cloth.collision_stride = static_cast<uint32_t>(opt.collision_stride);
    if (opt.strain_limit_passes > 0) cloth.strain_limit_passes = static_cast<uint32_t>(opt.strain_limit_passes);
    // A frame a little longer than 1/30 s must not hit the per-step cap (which would lengthen
    // every substep instead of adding some).
    const uint32_t per_frame = static_cast<uint32_t>(std::ceil(cloth.substep_hz / 30.0f));
    cloth.max_substeps = std::max(cloth.max_substeps, std::min<uint32_t>(1000, 2 * per_frame));
    if (!opt.garment_obj.empty()) {
      drape_mesh_fit fit;
      drape_mesh_fit_init(&fit);
      if (drape_result r = drape_context_add_garment_obj_file(ctx.get(), opt.garment_obj.c_str(), &fit, &gdesc, &cloth,
                                                              &garment)) {
        if (isFatalLibraryError(r))
          return fail(kExitFailure, "drape_context_add_garment_obj_file failed: " + libraryReason(r));
        if (r == DRAPE_ERROR_IO)
          return fail(kExitUsage, "cannot read the garment OBJ (" + libraryReason(r) + "); check the --garment path");
        return fail(kExitUsage, "the garment OBJ was refused (" + libraryReason(r) +
                                    "); pass a Wavefront OBJ garment made for a MakeHuman-like body (docs/garment-obj.md)");
      }
    } else {
      drape_garment_template tmpl;
      drape_garment_template_init(&tmpl);
      tmpl.kind = opt.garment_kind;
      if (opt.particles != 0) tmpl.particles = opt.particles;
      if (drape_result r = drape_context_add_garment_template(ctx.get(), &gdesc, &tmpl, &cloth, &garment)) {
        if (isFatalLibraryError(r))
          return fail(kExitFailure, "drape_context_add_garment_template failed: " + libraryReason(r));
        return fail(kExitUsage, std::string("the ") + replay::garmentKindName(opt.garment_kind) +
                                    " garment was refused (" + libraryReason(r) +
                                    "); try another --particles, --substeps or --garment");
      }
    }
  }

  // --under: a template worn under the garment (layers 1 and 2), with the same particles and cloth.
  drape_garment* under = nullptr;
  if (garment != nullptr && opt.under_kind >= 0) {
    drape_garment_desc udesc;
    drape_garment_desc_init(&udesc);
    drape_garment_template utmpl;
    drape_garment_template_init(&utmpl);
    utmpl.kind = opt.under_kind;
    if (opt.particles != 0) utmpl.particles = opt.particles;
    udesc.solver = opt.solver;
    udesc.cut = opt.garment_cut;
    if (drape_result r = drape_context_add_garment_template(ctx.get(), &udesc, &utmpl, &cloth, &under)) {
      if (isFatalLibraryError(r))
        return fail(kExitFailure, "drape_context_add_garment_template (--under) failed: " + libraryReason(r));
      return fail(kExitUsage, std::string("the ") + replay::garmentKindName(opt.under_kind) +
                                  " garment (--under) was refused (" + libraryReason(r) + ")");
    }
    if (drape_result r = drape_garment_set_layer(under, 1))
      return fail(kExitFailure, "drape_garment_set_layer failed: " + libraryReason(r));
    if (drape_result r = drape_garment_set_layer(garment, 2))
      return fail(kExitFailure, "drape_garment_set_layer failed: " + libraryReason(r));
  }

  ReplayStats st;
  st.drape_version = drape_version_string();
  st.recording = path;
  st.format = info.format;
  st.layout = info.layout;
  st.recording_frames = info.frame_count;
  st.recording_rate_hz = info.nominal_rate_hz;
  st.ring_points = desc.ring_points;
  st.proxy_rule = desc.proxy_rule;
  st.arm_clearance_m = desc.arms_clear_torso ? desc.arm_torso_clearance_m : -1.0;
  st.garment_fit_by_kind = opt.garment_cut == DRAPE_GARMENT_CUT_BY_KIND;
  if (garment != nullptr) {
    // What the garment is cut for (its cut resolved by the library: by kind, or the context's).
    drape_garment_stats gs0{};
    gs0.struct_size = sizeof gs0;
    if (drape_result r = drape_garment_get_stats(garment, &gs0))
      return fail(kExitFailure, "drape_garment_get_stats failed: " + libraryReason(r));
    st.garment_fit = gs0.cut;
  }
  if (opt.backend == "opencl") {
    // OpenCL for the cloth; without a working device the library falls back to the CPU and says
    // why: the replay goes on and the stats record it (backend "cpu", backend_fallback).
    drape_backend_desc bdesc;
    drape_backend_desc_init(&bdesc);
    bdesc.backend = DRAPE_BACKEND_OPENCL;
    if (drape_result r = drape_context_set_backend(ctx.get(), &bdesc))
      return fail(kExitFailure, "drape_context_set_backend failed: " + libraryReason(r));
  }
  {
    drape_backend_info binfo;
    binfo.struct_size = sizeof(binfo);
    if (drape_result r = drape_context_get_backend_info(ctx.get(), &binfo))
      return fail(kExitFailure, "drape_context_get_backend_info failed: " + libraryReason(r));
    st.backend = binfo.active == DRAPE_BACKEND_OPENCL ? "opencl" : "cpu";
    if (binfo.active == DRAPE_BACKEND_OPENCL) st.device = binfo.device_name;
    st.backend_fallback = binfo.fallback_reason;
    if (!st.backend_fallback.empty())
      std::fprintf(stderr, "drape-replay: OpenCL not used, the cloth runs on the CPU: %s\n", st.backend_fallback.c_str());
  }
  if (drape_result r = drape_context_get_ellipsoid_count(ctx.get(), &st.proxy_count))
    return fail(kExitFailure, "drape_context_get_ellipsoid_count failed: " + libraryReason(r));
  drape_body_shape_init(&st.shape);
  if (drape_result r = drape_context_get_body_shape(ctx.get(), &st.shape))
    return fail(kExitFailure, "drape_context_get_body_shape failed: " + libraryReason(r));

  uint32_t vertex_count = 0, index_count = 0;
  if (drape_result r = drape_context_get_body_mesh_size(ctx.get(), &vertex_count, &index_count))
    return fail(kExitFailure, "drape_context_get_body_mesh_size failed: " + libraryReason(r));
  st.vertices = vertex_count;
  st.triangles = index_count / 3;

  // Outputs: create directories before spending time on the replay.
  const std::string stats_path = replay::resolveStatsPath(opt);
  const uint32_t frames = opt.max_frames == 0 ? info.frame_count : std::min(opt.max_frames, info.frame_count);
  // The body's surface stretch is measured against the body once its bone lengths are calibrated
  // (before that the body's proportions are still being measured), or the last frame's of a
  // shorter run.
  st.body_stretch_from_frame = frames == 0 ? 0u : std::min(desc.calibration_frames, frames - 1);
  const bool render_due = replay::resolveRenderEvery(opt, frames) != 0;
  if ((opt.write_obj || render_due) && !ensureDirectory(opt.out_dir, error)) return fail(kExitUsage, error);
  if (!stats_path.empty() && !ensureDirectory(fs::path(stats_path).parent_path(), error))
    return fail(kExitUsage, error);

  std::vector<drape_joint> joints(info.joint_count);
  std::vector<drape_vec3> positions(vertex_count), normals(vertex_count);
  // The topology is fixed for a context (drape.h): read and check it once, not every frame.
  std::vector<uint32_t> indices(index_count);
  if (drape_result r = drape_context_read_body_mesh(ctx.get(), nullptr, nullptr, 0, indices.data(), index_count))
    return fail(kExitFailure, "drape_context_read_body_mesh (indices) failed: " + libraryReason(r));
  const bool watertight = replay::isWatertight(indices, vertex_count);

  // Garment mesh: sizes, indices and rest shape are fixed for the garment; read them once.
  GarmentMesh garment_mesh;
  if (garment) {
    if (!garment_mesh.load(garment, opt.write_obj || render_due, "", error)) return fail(kExitFailure, error);
    std::vector<drape_vec3> rest(garment_mesh.vertices);
    if (drape_result r = drape_garment_read_rest_positions(garment, rest.data(), garment_mesh.vertices))
      return fail(kExitFailure, "drape_garment_read_rest_positions failed: " + libraryReason(r));
    st.nonfinite += replay::countNonFinite(rest);
    st.stretch.setMesh(garment_mesh.indices, rest);

    drape_cloth_params actual;
    drape_cloth_params_init(&actual);
    if (drape_result r = drape_garment_get_params(garment, &actual))
      return fail(kExitFailure, "drape_garment_get_params failed: " + libraryReason(r));
    drape_garment_stats gs{};
    gs.struct_size = sizeof gs;
    if (drape_result r = drape_garment_get_stats(garment, &gs))
      return fail(kExitFailure, "drape_garment_get_stats failed: " + libraryReason(r));
    st.has_garment = true;
    st.garment_from_obj = !opt.garment_obj.empty();
    st.garment_kind = st.garment_from_obj ? opt.garment_obj : replay::garmentKindName(opt.garment_kind);
    st.solver = opt.solver;
    st.substep_hz = actual.substep_hz;
    st.iterations = actual.iterations;
    st.strain_limit = actual.strain_limit;
    st.collision_stride = actual.collision_stride;
    st.strain_limit_passes = actual.strain_limit_passes;
    st.particles = garment_mesh.vertices;
    st.garment_triangles = garment_mesh.index_count / 3;
    st.attached = gs.attached;
    st.cloth_ms.reserve(frames);
    st.integrate_ms.reserve(frames);
    st.collide_ms.reserve(frames);
    st.contacts.reserve(frames);
    st.substeps.reserve(frames);
  }
  // The host's frame time for drape_context_step: this frame's timestamp minus the previous
  // accepted frame's; the first frame gets one nominal frame period.
  const double first_dt = std::isfinite(info.nominal_rate_hz) && info.nominal_rate_hz > 0.0f
                              ? 1.0 / static_cast<double>(info.nominal_rate_hz)
                              : 1.0 / 30.0;
  bool have_previous = false;
  double previous_timestamp = 0.0;
  st.ms_per_frame.reserve(frames);
  st.skeleton_ms.reserve(frames);
  st.body_ms.reserve(frames);
  st.volume_l.reserve(frames);
  constexpr uint32_t kMaxRejectionMessages = 5;

  // --under: its mesh (indices once; positions and normals per frame) and the ellipsoids its
  // crossing is measured against.
  GarmentMesh under_mesh;
  std::vector<drape_ellipsoid> ellipsoids;
  uint32_t ellipsoid_capacity = 0;
  if (under) {
    if (!under_mesh.load(under, opt.write_obj || render_due, " (--under)", error)) return fail(kExitFailure, error);
    uint32_t ne = 0;
    if (drape_result r = drape_context_get_ellipsoid_count(ctx.get(), &ne))
      return fail(kExitFailure, "drape_context_get_ellipsoid_count failed: " + libraryReason(r));
    ellipsoid_capacity = ne;
    st.has_under = true;
    st.under_kind = replay::garmentKindName(opt.under_kind);
    st.under_particles = under_mesh.vertices;
  }

  // Pictures (drawn outside the timed calls) and the progress bar (a terminal only).
  replay::Pictures pictures;
  pictures.begin(opt, frames, info.nominal_rate_hz, fs::path(path).filename().string(),
                 garment ? (st.garment_from_obj ? fs::path(opt.garment_obj).filename().string() : st.garment_kind) +
                               (under ? " OVER " + st.under_kind : std::string())
                         : std::string("NO GARMENT"),
                 st.render);
  if (render_due && !st.render.png_available && !opt.quiet)
    std::fprintf(stderr, "drape-replay: note: built without stb_image_write, so no pictures; install libstb-dev "
                         "(bash .ci/install-deps.sh) and rebuild\n");
  if (under) pictures.setUnderGarment(&under_mesh.positions, &under_mesh.normals, &under_mesh.indices);
  replay::ProgressBar progress(frames, !opt.quiet && replay::stderrIsTerminal());
  double frame_timestamp = 0.0;
  auto renderFrame = [&](uint32_t index) {
    if (!pictures.active()) return true;
    static const std::vector<drape_vec3> kNoVertices;
    static const std::vector<uint32_t> kNoIndices;
    return pictures.addFrame(index, frame_timestamp, positions, normals, indices,
                             garment ? garment_mesh.positions : kNoVertices, garment ? garment_mesh.normals : kNoVertices,
                             garment ? garment_mesh.indices : kNoIndices, st.render, error);
  };

  using Clock = std::chrono::steady_clock;
  for (uint32_t i = 0; i < frames; ++i) {
    progress.update(i);
    double timestamp = 0.0;
    if (drape_result r = drape_recording_read_frame(rec.get(), i, joints.data(),
                                                    static_cast<uint32_t>(joints.size()), &timestamp))
      return fail(kExitFailure, "drape_recording_read_frame(" + std::to_string(i) + ") failed: " + libraryReason(r));
    drape_skeleton_frame frame{};
    frame.struct_size = sizeof frame;
    frame.layout = info.layout;
    frame.joint_count = info.joint_count;
    frame.reserved = 0;
    frame.timestamp_s = timestamp;
    frame.joints = joints.data();
    frame.orientations = nullptr;
    ++st.frames;

    const Clock::time_point t0 = Clock::now();
    if (drape_result r = drape_context_push_skeleton(ctx.get(), &frame)) {
      if (isFatalLibraryError(r))
        return fail(kExitFailure, "drape_context_push_skeleton failed on frame " + std::to_string(i) + ": " +
                                      libraryReason(r));
      if (!opt.quiet && st.rejected_frames < kMaxRejectionMessages) progress.finish();
      if (!opt.quiet && st.rejected_frames < kMaxRejectionMessages)
        std::fprintf(stderr, "drape-replay: frame %u rejected: %s%s\n", i, libraryReason(r).c_str(),
                     st.rejected_frames + 1 == kMaxRejectionMessages ? " (further rejections not shown)" : "");
      ++st.rejected_frames;
      continue;
    }
    if (garment) {
      // drape_context_step runs the update, then the cloth. dt within the library's (0, 10] s.
      const double dt = std::min(std::max(have_previous ? timestamp - previous_timestamp : first_dt, 1e-6), 10.0);
      if (drape_result r = drape_context_step(ctx.get(), static_cast<float>(dt)))
        return fail(kExitFailure, "drape_context_step failed on frame " + std::to_string(i) + ": " + libraryReason(r));
    } else if (drape_result r = drape_context_update(ctx.get())) {
      return fail(kExitFailure, "drape_context_update failed on frame " + std::to_string(i) + ": " + libraryReason(r));
    }
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    st.ms_per_frame.push_back(ms);
    // Sampled before this frame's reads (mesh, fidelity) build what the update skipped.
    drape_skip_stats skip{};
    skip.struct_size = sizeof skip;
    if (drape_result r = drape_context_get_skip_stats(ctx.get(), &skip))
      return fail(kExitFailure, "drape_context_get_skip_stats failed: " + libraryReason(r));
    st.proxies_built.push_back(skip.proxies_built);
    have_previous = true;
    previous_timestamp = timestamp;

    drape_frame_stats fs_stats{};
    fs_stats.struct_size = sizeof fs_stats;
    if (drape_result r = drape_context_get_frame_stats(ctx.get(), &fs_stats))
      return fail(kExitFailure, "drape_context_get_frame_stats failed: " + libraryReason(r));
    st.nonfinite += static_cast<uint64_t>(!std::isfinite(fs_stats.skeleton_ms)) +
                    static_cast<uint64_t>(!std::isfinite(fs_stats.body_ms)) +
                    static_cast<uint64_t>(!std::isfinite(fs_stats.body_volume_l));
    st.skeleton_ms.push_back(fs_stats.skeleton_ms);
    st.body_ms.push_back(fs_stats.body_ms);
    st.proxies_ms.push_back(fs_stats.proxies_ms);
    st.nonfinite += static_cast<uint64_t>(!std::isfinite(fs_stats.proxies_ms));

    if (opt.fidelity_every != 0 && (st.ms_per_frame.size() - 1) % opt.fidelity_every == 0) {
      drape_proxy_fidelity fid{};
      fid.struct_size = sizeof fid;
      if (drape_result r = drape_context_measure_proxy_fidelity(ctx.get(), &fid))
        return fail(kExitFailure, "drape_context_measure_proxy_fidelity failed: " + libraryReason(r));
      st.body_to_proxy_p95.push_back(fid.body_to_proxy_p95_mm);
      st.proxy_to_body_p95.push_back(fid.proxy_to_body_p95_mm);
      st.fit_max.push_back(std::max(fid.body_to_proxy_max_mm, fid.proxy_to_body_max_mm));
      st.outside_fraction.push_back(fid.outside_fraction);
    }

    if (drape_result r = drape_context_read_body_mesh(ctx.get(), positions.data(), normals.data(), vertex_count,
                                                      nullptr, 0))
      return fail(kExitFailure, "drape_context_read_body_mesh failed on frame " + std::to_string(i) + ": " +
                                    libraryReason(r));
    st.nonfinite += replay::countNonFinite(positions) + replay::countNonFinite(normals);
    if (watertight) ++st.watertight_frames;
    // The library's own divergence-theorem volume (computed when the stats are read).
    if (std::isfinite(fs_stats.body_volume_l)) st.volume_l.push_back(fs_stats.body_volume_l);

    if (opt.write_obj) {
      const fs::path obj = fs::path(opt.out_dir) / replay::objFileName(i);
      const std::string comment = "drape-replay frame " + std::to_string(i) + ", t = " + std::to_string(timestamp) +
                                  " s, " + std::to_string(vertex_count) + " vertices";
      if (!replay::writeObj(obj.string(), positions, normals, indices, comment, error))
        return fail(kExitFailure, error);
    }

    frame_timestamp = timestamp;
    if (!garment) {
      if (!renderFrame(i)) return fail(kExitFailure, error);
      continue;
    }
    drape_garment_stats gs{};
    gs.struct_size = sizeof gs;
    if (drape_result r = drape_garment_get_stats(garment, &gs))
      return fail(kExitFailure, "drape_garment_get_stats failed: " + libraryReason(r));
    st.nonfinite += static_cast<uint64_t>(!std::isfinite(gs.step_ms)) +
                    static_cast<uint64_t>(!std::isfinite(gs.integrate_ms)) +
                    static_cast<uint64_t>(!std::isfinite(gs.collide_ms));
    st.cloth_ms.push_back(gs.step_ms);
    st.integrate_ms.push_back(gs.integrate_ms);
    st.collide_ms.push_back(gs.collide_ms);
    st.device_upload_ms.push_back(gs.device_upload_ms);
    st.device_kernel_ms.push_back(gs.device_kernel_ms);
    st.device_readback_ms.push_back(gs.device_readback_ms);
    st.device_host_ms.push_back(gs.device_host_ms);
    st.contacts.push_back(gs.contacts);
    st.substeps.push_back(gs.substeps);
    st.teleport_resets += gs.teleport_reset ? 1u : 0u;
    if (gs.refits != st.refits) {
      // Cut again (the skeleton's calibration): stretch from now on is against the new rest shape.
      std::vector<drape_vec3> rest(garment_mesh.vertices);
      if (drape_result r = drape_garment_read_rest_positions(garment, rest.data(), garment_mesh.vertices))
        return fail(kExitFailure, "drape_garment_read_rest_positions failed: " + libraryReason(r));
      st.nonfinite += replay::countNonFinite(rest);
      st.stretch.setRest(rest);
      st.refits = gs.refits;
      st.garment_fit = gs.cut;  // a garment cut by kind may have changed cut (a shape too small)
    }
    st.nan_resets += gs.nan_reset ? 1u : 0u;

    if (opt.measure_every != 0 && (st.cloth_ms.size() - 1) % opt.measure_every == 0) {
      drape_garment_accuracy acc{};
      acc.struct_size = sizeof acc;
      if (drape_result r = drape_garment_measure(garment, &acc))
        return fail(kExitFailure, "drape_garment_measure failed on frame " + std::to_string(i) + ": " +
                                      libraryReason(r));
      const float measured[] = {acc.max_stretch, acc.p99_stretch, acc.mean_stretch, acc.body_penetration_p99_mm,
                                acc.body_penetration_max_mm, acc.deeper_than_2mm, acc.inside_body};
      for (float v : measured) st.nonfinite += static_cast<uint64_t>(!std::isfinite(v));
      st.proxy_inside += acc.proxy_inside;
      st.penetration_p99_mm.push_back(acc.body_penetration_p99_mm);
      st.penetration_max_mm.push_back(acc.body_penetration_max_mm);
      st.deeper_than_2mm.push_back(acc.deeper_than_2mm);
      st.inside_body.push_back(acc.inside_body);
      st.openings = acc.openings;
      st.openings_off_frames += acc.openings_off > 0 ? 1u : 0u;
      st.openings_off_max = std::max(st.openings_off_max, acc.openings_off);
    }

    if (!garment_mesh.read(garment, i, "", error)) return fail(kExitFailure, error);
    st.nonfinite += replay::countNonFinite(garment_mesh.positions) + replay::countNonFinite(garment_mesh.normals);
    st.stretch.addFrame(garment_mesh.positions);
    if (!st.body_stretch_set && i >= st.body_stretch_from_frame) {
      const std::vector<uint32_t> covered = replay::trianglesNear(
          indices, positions, garment_mesh.positions, replay::ReplayStats::kBodyUnderGarmentM,
          replay::ReplayStats::kBodyMinEdgeM);
      st.body_stretch.setMesh(covered, positions);
      st.body_tube_stretch.setMesh(covered, positions, st.ring_points + 1);
      st.body_stretch_set = true;
    }
    if (st.body_stretch_set) {
      st.body_stretch.addFrame(positions);
      st.body_tube_stretch.addFrame(positions);
    }

    if (under) {
      if (!under_mesh.read(under, i, " (--under)", error)) return fail(kExitFailure, error);
      st.nonfinite += replay::countNonFinite(under_mesh.positions) + replay::countNonFinite(under_mesh.normals);
      if (opt.measure_every != 0 && (st.cloth_ms.size() - 1) % opt.measure_every == 0) {
        uint32_t got = 0;
        ellipsoids.resize(ellipsoid_capacity);  // the context's count, fixed by its body
        if (drape_result r = drape_context_read_ellipsoids(ctx.get(), ellipsoids.data(), ellipsoid_capacity, &got))
          return fail(kExitFailure, "drape_context_read_ellipsoids failed: " + libraryReason(r));
        ellipsoids.resize(got);
        replay::addLayerCrossing(garment_mesh.positions, under_mesh.positions, ellipsoids, st.layer_crossing);
      }
    }
    if (opt.write_obj) {
      // This frame's garment OBJ (and the one under it), its comment naming what it is.
      const auto writeGarment = [&](const std::string& file, const std::string& what,
                                    const std::vector<drape_vec3>& p, const std::vector<drape_vec3>& n,
                                    const std::vector<uint32_t>& idx) {
        const std::string comment = "drape-replay garment " + what + ", frame " + std::to_string(i) + ", t = " +
                                    std::to_string(timestamp) + " s, " + std::to_string(p.size()) + " vertices";
        return replay::writeObj((fs::path(opt.out_dir) / file).string(), p, n, idx, comment, error);
      };
      if (under && !writeGarment(replay::underObjFileName(i), "under (" + st.under_kind + ")", under_mesh.positions,
                                 under_mesh.normals, under_mesh.indices))
        return fail(kExitFailure, error);
      if (!writeGarment(replay::garmentObjFileName(i), st.garment_kind, garment_mesh.positions, garment_mesh.normals,
                        garment_mesh.indices))
        return fail(kExitFailure, error);
    }
    if (!renderFrame(i)) return fail(kExitFailure, error);
  }
  progress.update(frames);
  if (!pictures.finish(st.render, error)) return fail(kExitFailure, error);
  progress.finish();

  drape_frame_stats final_stats{};
  final_stats.struct_size = sizeof final_stats;
  if (drape_result r = drape_context_get_frame_stats(ctx.get(), &final_stats))
    return fail(kExitFailure, "drape_context_get_frame_stats failed: " + libraryReason(r));
  st.teleports = final_stats.teleports;
  st.pose_jumps = final_stats.pose_jumps;
  st.full_pipeline = opt.full_pipeline;
  drape_skip_stats final_skip{};
  final_skip.struct_size = sizeof final_skip;
  if (drape_result r = drape_context_get_skip_stats(ctx.get(), &final_skip))
    return fail(kExitFailure, "drape_context_get_skip_stats failed: " + libraryReason(r));
  st.proxies_available = final_skip.proxies_available;
  st.stages_skipped = final_skip.stages_skipped;
  st.frames_slept = final_skip.frames_slept;

  if (!stats_path.empty()) {
    const std::string json = replay::statsJson(st);
    std::FILE* f = std::fopen(stats_path.c_str(), "wb");
    const bool ok = f && std::fwrite(json.data(), 1, json.size(), f) == json.size();
    if (f && std::fclose(f) != 0) return fail(kExitFailure, "cannot write stats file '" + stats_path + "'");
    if (!ok) return fail(kExitFailure, "cannot write stats file '" + stats_path + "'; check --stats/--out");
  }
  if (!opt.quiet)
    std::fputs(replay::summaryText(st, opt.write_obj ? opt.out_dir : std::string(), stats_path).c_str(), stdout);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // std::bad_alloc, filesystem errors
    return fail(kExitFailure, std::string("unexpected failure: ") + e.what());
  }
}
