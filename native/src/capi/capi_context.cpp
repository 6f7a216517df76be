// C entry points for contexts: creation, body shape, skeleton input, update and reads.
#include "capi/api_support.h"
#include "capi/context.h"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <memory>

using drape::Context;
using namespace drape::api;

namespace drape::api {
void forgetGarments(Context& ctx);  // capi_garments.cpp
}  // namespace drape::api

namespace {

#define DRAPE_CHECK_CONTEXT(fn, handle) DRAPE_RESOLVE_CONTEXT(self, fn, handle)

drape_result toShapeInput(const drape_body_shape& s, drape::BodyShapeInput& in) {
  in.sex = static_cast<drape::Sex>(s.sex);
  if (s.sex < DRAPE_SEX_UNSPECIFIED || s.sex > DRAPE_SEX_MALE)
    return fail(DRAPE_ERROR_OUT_OF_RANGE, "body shape: sex must be 0 (unspecified), 1 (female) or 2 (male)");
  in.height_m = s.height_m;
  in.weight_kg = s.weight_kg;
  const float g[drape::kGirthCount] = {s.neck_mm, s.chest_mm, s.waist_mm, s.hip_mm,
                                       s.thigh_mm, s.calf_mm, s.upper_arm_mm, s.forearm_mm};
  std::copy(g, g + drape::kGirthCount, in.girth_mm.begin());
  return DRAPE_OK;
}

}  // namespace

extern "C" {

DRAPE_API drape_result DRAPE_CALL drape_context_desc_init_sized(drape_context_desc* desc, uint32_t struct_size) {
  if (drape_result r = checkSizedInit("drape_context_desc_init_sized", desc, "desc", struct_size,
                                      DRAPE_CONTEXT_DESC_SIZE_V1, sizeof(drape_context_desc)))
    return r;
  drape_context_desc d;
  std::memset(&d, 0, sizeof(d));
  const drape::TrackerParams t;
  d.struct_size = struct_size;
  d.ring_points = 20;
  d.rings_per_segment = 1;
  d.calibration_frames = static_cast<uint32_t>(t.calibration_frames);
  d.filter = DRAPE_FILTER_ONE_EURO;
  d.filter_min_cutoff_hz = t.min_cutoff_hz;
  d.filter_beta = t.beta;
  d.filter_d_cutoff_hz = t.d_cutoff_hz;
  d.smoothing = t.smoothing;
  d.correction = t.correction;
  d.prediction = t.prediction;
  d.jitter_radius_m = t.jitter_radius_m;
  d.max_deviation_m = t.max_deviation_m;
  d.teleport_distance_m = t.teleport_distance_m;
  d.proxy_rule = DRAPE_PROXY_RULE_DRAPE;
  d.arms_clear_torso = 1;
  d.arm_torso_clearance_m = drape::kDefaultArmTorsoClearanceM;
  std::memcpy(desc, &d, struct_size);
  return DRAPE_OK;
}

// The header maps drape_context_desc_init to the sized init with the caller's sizeof; this is the
// exported symbol that hosts built before the sized init call: the 72 bytes the struct had then
// (8 more than a host of the 64-byte first layout, older still, has: drape.h's conventions).
#undef drape_context_desc_init
constexpr uint32_t kContextDescSizeOfTheExportedInit = 72;
static_assert(sizeof(drape_context_desc) >= kContextDescSizeOfTheExportedInit,
              "the exported init's layout is a prefix of the struct");
DRAPE_API drape_result DRAPE_CALL drape_context_desc_init(drape_context_desc* desc) {
  if (!desc) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_desc_init: desc is NULL");
  return drape_context_desc_init_sized(desc, kContextDescSizeOfTheExportedInit);
}

DRAPE_API drape_result DRAPE_CALL drape_context_create(const drape_context_desc* desc,
                                                       drape_context** out_context) {
  return guarded("drape_context_create", [&]() -> drape_result {
    if (!out_context) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_create: out_context is NULL");
    drape_context_desc d;
    drape_context_desc_init_sized(&d, sizeof(d));
    if (desc) {
      if (drape_result r = checkStructSize(desc->struct_size, DRAPE_CONTEXT_DESC_SIZE_V1, "drape_context_desc"))
        return r;
      // A caller's desc of an earlier layout: the fields its struct_size covers whole, the later
      // ones' defaults (left by init).
      std::memcpy(&d, desc, DRAPE_CONTEXT_DESC_SIZE_V1);
      auto covers = [&](size_t offset, size_t size) { return desc->struct_size >= offset + size; };
      if (covers(offsetof(drape_context_desc, arms_clear_torso), sizeof(d.arms_clear_torso)))
        d.arms_clear_torso = desc->arms_clear_torso;
      if (covers(offsetof(drape_context_desc, arm_torso_clearance_m), sizeof(d.arm_torso_clearance_m)))
        d.arm_torso_clearance_m = desc->arm_torso_clearance_m;
      d.struct_size = sizeof(drape_context_desc);
    }
    std::string err;
    if (drape_result r = drape::validateContextDesc(d, err)) return fail(r, "drape_context_create: " + err);
    auto ctx = std::make_unique<Context>(d);
    void* token = registerHandle(HandleKind::Context, ctx.get());
    ctx.release();  // owned by the registry entry until drape_context_destroy
    *out_context = static_cast<drape_context*>(token);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_destroy(drape_context* context) {
  return guarded("drape_context_destroy", [&]() -> drape_result {
    if (!context) return DRAPE_OK;
    auto* ctx = static_cast<Context*>(unregisterHandle(HandleKind::Context, context));
    if (!ctx) return fail(DRAPE_ERROR_INVALID_HANDLE, "drape_context_destroy: context is not a live drape_context");
    forgetGarments(*ctx);
    delete ctx;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_body_shape_init(drape_body_shape* shape) {
  if (!shape) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_body_shape_init: shape is NULL");
  std::memset(shape, 0, sizeof(*shape));
  const drape::BodyShapeInput defaults;
  shape->struct_size = sizeof(drape_body_shape);
  shape->sex = DRAPE_SEX_UNSPECIFIED;
  shape->height_m = defaults.height_m;
  shape->weight_kg = defaults.weight_kg;
  return DRAPE_OK;
}

DRAPE_API drape_result DRAPE_CALL drape_context_set_body_shape(drape_context* context,
                                                               const drape_body_shape* shape) {
  return guarded("drape_context_set_body_shape", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_set_body_shape", context);
    if (!shape) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_set_body_shape: shape is NULL");
    if (drape_result r = checkStructSize(shape->struct_size, sizeof(drape_body_shape), "drape_body_shape")) return r;
    drape::BodyShapeInput in;
    if (drape_result r = toShapeInput(*shape, in)) return r;
    std::string err;
    if (drape_result r = self->setShape(in, err)) return fail(r, "drape_context_set_body_shape: " + err);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_body_shape(drape_context* context,
                                                               drape_body_shape* out_shape) {
  return guarded("drape_context_get_body_shape", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_get_body_shape", context);
    if (!out_shape) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_body_shape: out_shape is NULL");
    if (drape_result r = checkStructSize(out_shape->struct_size, sizeof(drape_body_shape), "drape_body_shape")) return r;
    const drape::ResolvedShape& s = self->shape();
    drape_body_shape o;
    std::memset(&o, 0, sizeof(o));
    o.struct_size = sizeof(drape_body_shape);
    o.sex = static_cast<int32_t>(s.input.sex);
    o.height_m = s.input.height_m;
    o.weight_kg = s.input.weight_kg;
    float* g[drape::kGirthCount] = {&o.neck_mm, &o.chest_mm, &o.waist_mm, &o.hip_mm,
                                    &o.thigh_mm, &o.calf_mm, &o.upper_arm_mm, &o.forearm_mm};
    // Girths the host gave come back bit-exact; predicted ones in mm.
    for (int i = 0; i < drape::kGirthCount; ++i)
      *g[i] = s.girth_given[i] ? s.input.girth_mm[i] : 1000.0f * s.m[i];
    *out_shape = o;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_push_skeleton(drape_context* context,
                                                              const drape_skeleton_frame* frame) {
  return guarded("drape_context_push_skeleton", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_push_skeleton", context);
    if (!frame) {
      self->countRejectedFrame();
      return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_push_skeleton: frame is NULL");
    }
    if (drape_result r = checkStructSize(frame->struct_size, sizeof(drape_skeleton_frame), "drape_skeleton_frame")) {
      self->countRejectedFrame();
      return r;
    }
    std::string err;
    if (drape_result r = self->pushFrame(*frame, err))
      return fail(r, "drape_context_push_skeleton: " + err);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_update(drape_context* context) {
  return guarded("drape_context_update", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_update", context);
    std::string err;
    if (drape_result r = self->update(err)) return fail(r, "drape_context_update: " + err);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_read_skeleton(drape_context* context, drape_vec3* positions,
                                                              uint32_t capacity, uint32_t* out_count) {
  return guarded("drape_context_read_skeleton", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_read_skeleton", context);
    if (!positions) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_skeleton: positions is NULL");
    if (capacity < static_cast<uint32_t>(drape::kJointCount))
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_context_read_skeleton: capacity " + std::to_string(capacity) +
                                                    " is below 21 joints");
    Context* ctx = self;
    if (!ctx->hasUpdate())
      return fail(DRAPE_ERROR_CALL_ORDER, "drape_context_read_skeleton: no update has run yet");
    const auto& pose = ctx->tracker().pose();
    for (int j = 0; j < drape::kJointCount; ++j)
      positions[j] = drape_vec3{pose.position[j].x(), pose.position[j].y(), pose.position[j].z()};
    if (out_count) *out_count = static_cast<uint32_t>(drape::kJointCount);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_body_mesh_size(drape_context* context,
                                                                   uint32_t* out_vertex_count,
                                                                   uint32_t* out_index_count) {
  return guarded("drape_context_get_body_mesh_size", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_get_body_mesh_size", context);
    if (!out_vertex_count && !out_index_count)
      return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_body_mesh_size: both out pointers are NULL");
    const drape::BodyModel& body = self->body();
    if (out_vertex_count) *out_vertex_count = static_cast<uint32_t>(body.positions().size());
    if (out_index_count) *out_index_count = static_cast<uint32_t>(body.indices().size());
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_read_body_mesh(drape_context* context, drape_vec3* positions,
                                                               drape_vec3* normals, uint32_t vertex_capacity,
                                                               uint32_t* indices, uint32_t index_capacity) {
  return guarded("drape_context_read_body_mesh", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_read_body_mesh", context);
    if (!positions && !normals && !indices)
      return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_read_body_mesh: positions, normals and indices are all NULL");
    Context* ctx = self;
    const drape::BodyModel& body = ctx->body();
    const size_t nv = body.positions().size(), ni = body.indices().size();
    // Check everything before writing anything.
    if ((positions || normals) && vertex_capacity < nv)
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_context_read_body_mesh: vertex_capacity " +
                                                    std::to_string(vertex_capacity) + " < " + std::to_string(nv) + " vertices");
    if (indices && index_capacity < ni)
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, "drape_context_read_body_mesh: index_capacity " +
                                                    std::to_string(index_capacity) + " < " + std::to_string(ni) + " indices");
    if ((positions || normals) && !ctx->hasUpdate())
      return fail(DRAPE_ERROR_CALL_ORDER,
                  "drape_context_read_body_mesh: positions and normals exist after the first successful update");
    // Stages on demand: the mesh (and normals) of the last update are computed now if skipped.
    if (positions || normals) ctx->bodyMesh(normals != nullptr);
    static_assert(sizeof(drape_vec3) == 3 * sizeof(float), "drape_vec3 must be three packed floats");
    if (positions)
      for (size_t i = 0; i < nv; ++i) {
        const auto& p = body.positions()[i];
        positions[i] = drape_vec3{p.x(), p.y(), p.z()};
      }
    if (normals)
      for (size_t i = 0; i < nv; ++i) {
        const auto& n = body.normals()[i];
        normals[i] = drape_vec3{n.x(), n.y(), n.z()};
      }
    if (indices) std::copy(body.indices().begin(), body.indices().end(), indices);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_frame_stats(drape_context* context,
                                                                drape_frame_stats* out_stats) {
  return guarded("drape_context_get_frame_stats", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_get_frame_stats", context);
    if (!out_stats) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_frame_stats: out_stats is NULL");
    if (drape_result r = checkStructSize(out_stats->struct_size, sizeof(drape_frame_stats), "drape_frame_stats"))
      return r;
    drape_frame_stats s;
    std::memset(&s, 0, sizeof(s));
    s.struct_size = sizeof(drape_frame_stats);
    self->fillStats(s);
    *out_stats = s;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_ellipsoid_count(drape_context* context, uint32_t* out_count) {
  return guarded("drape_context_get_ellipsoid_count", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_get_ellipsoid_count", context);
    if (!out_count) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_ellipsoid_count: out_count is NULL");
    *out_count = static_cast<uint32_t>(self->ellipsoidCount());
    return DRAPE_OK;
  });
}

namespace {
// Shared checks of the two ellipsoid readers; returns the ellipsoids to copy or sets `r`.
const std::vector<drape::Ellipsoid>* ellipsoidsToRead(const char* fn, Context* ctx, const void* out,
                                                      uint32_t capacity, drape_result& r) {
  const auto& e = ctx->proxies().ellipsoids();
  if (!out) {
    r = fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": output buffer is NULL");
  } else if (capacity < e.size()) {
    r = fail(DRAPE_ERROR_BUFFER_TOO_SMALL, std::string(fn) + ": capacity " + std::to_string(capacity) + " < " +
                                               std::to_string(e.size()) + " ellipsoids");
  } else if (!ctx->hasUpdate()) {
    r = fail(DRAPE_ERROR_CALL_ORDER, std::string(fn) + ": no update has run yet");
  } else {
    r = DRAPE_OK;
    return &e;
  }
  return nullptr;
}
drape_vec3 v3(const drape::Vec3& v) { return drape_vec3{v.x(), v.y(), v.z()}; }
}  // namespace

DRAPE_API drape_result DRAPE_CALL drape_context_read_ellipsoids(drape_context* context, drape_ellipsoid* ellipsoids,
                                                                uint32_t capacity, uint32_t* out_count) {
  return guarded("drape_context_read_ellipsoids", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_read_ellipsoids", context);
    drape_result r = DRAPE_OK;
    const auto* e = ellipsoidsToRead("drape_context_read_ellipsoids", self, ellipsoids, capacity, r);
    if (!e) return r;
    const auto& sources = self->proxies().sources();
    for (size_t i = 0; i < e->size(); ++i) {
      const drape::Ellipsoid& el = (*e)[i];
      ellipsoids[i] = drape_ellipsoid{v3(el.centre), v3(el.rotation.col(0)), v3(el.rotation.col(1)),
                                      v3(el.rotation.col(2)), v3(el.radii),
                                      static_cast<int32_t>(sources[i].chain), sources[i].first_ring};
    }
    if (out_count) *out_count = static_cast<uint32_t>(e->size());
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_read_ellipsoid_matrices(drape_context* context, float* matrices,
                                                                        uint32_t capacity, uint32_t* out_count) {
  return guarded("drape_context_read_ellipsoid_matrices", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_read_ellipsoid_matrices", context);
    drape_result r = DRAPE_OK;
    const auto* e = ellipsoidsToRead("drape_context_read_ellipsoid_matrices", self, matrices, capacity, r);
    if (!e) return r;
    for (size_t i = 0; i < e->size(); ++i) {
      const drape::Ellipsoid& el = (*e)[i];
      Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
      m.topLeftCorner<3, 3>() = el.rotation * el.radii.asDiagonal();
      m.topRightCorner<3, 1>() = el.centre;
      std::memcpy(matrices + 16 * i, m.data(), 16 * sizeof(float));  // Eigen is column-major
    }
    if (out_count) *out_count = static_cast<uint32_t>(e->size());
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_measure_proxy_fidelity(drape_context* context,
                                                                       drape_proxy_fidelity* out) {
  return guarded("drape_context_measure_proxy_fidelity", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_measure_proxy_fidelity", context);
    if (!out) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_measure_proxy_fidelity: out is NULL");
    if (drape_result r = checkStructSize(out->struct_size, sizeof(drape_proxy_fidelity), "drape_proxy_fidelity"))
      return r;
    Context* ctx = self;
    if (!ctx->hasUpdate())
      return fail(DRAPE_ERROR_CALL_ORDER, "drape_context_measure_proxy_fidelity: no update has run yet");
    const drape::FidelityReport f = ctx->measureFidelity();
    drape_proxy_fidelity o;
    std::memset(&o, 0, sizeof(o));
    o.struct_size = sizeof(o);
    o.union_samples = static_cast<uint32_t>(f.union_samples);
    o.body_to_proxy_mean_mm = f.body_to_union_mean_mm;
    o.body_to_proxy_p95_mm = f.body_to_union_p95_mm;
    o.body_to_proxy_max_mm = f.body_to_union_max_mm;
    o.proxy_to_body_mean_mm = f.union_to_body_mean_mm;
    o.proxy_to_body_p95_mm = f.union_to_body_p95_mm;
    o.proxy_to_body_max_mm = f.union_to_body_max_mm;
    o.outside_fraction = f.outside_fraction;
    *out = o;
    return DRAPE_OK;
  });
}

}  // extern "C"

// Layout guarantees the C# bindings (and any other FFI) rely on.
static_assert(sizeof(drape_vec3) == 12, "drape_vec3 layout");
static_assert(sizeof(drape_quat) == 16, "drape_quat layout");
static_assert(sizeof(drape_joint) == 16, "drape_joint layout");
static_assert(sizeof(drape_context_desc) == 72, "drape_context_desc layout");
static_assert(offsetof(drape_context_desc, arms_clear_torso) == DRAPE_CONTEXT_DESC_SIZE_V1,
              "drape_context_desc: the fields after the first layout are appended");
static_assert(sizeof(drape_ellipsoid) == 68, "drape_ellipsoid layout");
static_assert(sizeof(drape_proxy_fidelity) == 40, "drape_proxy_fidelity layout");
static_assert(sizeof(drape_body_shape) == 48, "drape_body_shape layout");
static_assert(sizeof(drape_skeleton_frame) == 24 + 2 * sizeof(void*), "drape_skeleton_frame layout");
static_assert(sizeof(drape_frame_stats) == 72, "drape_frame_stats layout");
static_assert(sizeof(drape_recording_info) == 32, "drape_recording_info layout");
static_assert(sizeof(drape_result) == 4, "enums are 32-bit");

// File-local (capi_garments.cpp defines its own; the sanitizer tree compiles both in one batch).
#undef DRAPE_CHECK_CONTEXT
