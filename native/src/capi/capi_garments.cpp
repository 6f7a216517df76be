// C entry points for garments: creation (template, OBJ, mesh), parameters, stepping, reads,
// statistics. Conversions between the C structs and the solver's parameter structs live here.
#include "capi/api_support.h"
#include "capi/context.h"
#include "cloth/garment_obj.h"
#include "cloth/garment_templates.h"

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <memory>
#include <sstream>

using drape::Context;
using drape::GarmentSim;
using namespace drape::api;

namespace {

#define DRAPE_CHECK_CONTEXT(fn, handle) DRAPE_RESOLVE_CONTEXT(ctx, fn, handle)

#define DRAPE_CHECK_GARMENT(fn, handle)                                                          \
  if (!(handle)) return fail(DRAPE_ERROR_NULL_ARGUMENT, fn ": garment is NULL");                 \
  GarmentSim* const garment = static_cast<GarmentSim*>(resolveHandle(HandleKind::Garment, handle)); \
  if (!garment)                                                                                  \
    return fail(DRAPE_ERROR_INVALID_HANDLE, fn ": garment is not a live drape_garment (destroyed, or its context was)")

// Range check shared by every struct below: NaN/Inf -> NONFINITE, outside -> OUT_OF_RANGE.
struct Checker {
  std::ostringstream msg;
  drape_result result = DRAPE_OK;
  void range(const char* what, const char* name, float v, float lo, float hi) {
    if (result != DRAPE_OK) return;
    if (!std::isfinite(v)) {
      msg << what << ": " << name << " is not finite";
      result = DRAPE_ERROR_NONFINITE;
    } else if (v < lo || v > hi) {
      msg << what << ": " << name << " = " << v << " is outside [" << lo << ", " << hi << "]";
      result = DRAPE_ERROR_OUT_OF_RANGE;
    }
  }
  void vec(const char* what, const char* name, const drape_vec3& v, float limit) {
    range(what, name, v.x, -limit, limit);
    range(what, name, v.y, -limit, limit);
    range(what, name, v.z, -limit, limit);
  }
  void reserved(const char* what, uint32_t v) {
    if (result == DRAPE_OK && v != 0) {
      msg << what << ": reserved must be 0";
      result = DRAPE_ERROR_INVALID_ARGUMENT;
    }
  }
  drape_result done(const char* fn) { return result == DRAPE_OK ? DRAPE_OK : fail(result, std::string(fn) + ": " + msg.str()); }
};

drape::Vec3 v3(const drape_vec3& v) { return drape::Vec3(v.x, v.y, v.z); }
drape_vec3 c3(const drape::Vec3& v) { return drape_vec3{v.x(), v.y(), v.z()}; }

drape_result toSimParams(const char* fn, const drape_cloth_params& c, drape::GarmentSimParams& out) {
  Checker k;
  const char* w = "cloth params";
  k.range(w, "substep_hz", c.substep_hz, 30.0f, 20000.0f);
  k.range(w, "max_substeps", static_cast<float>(c.max_substeps), 1.0f, 1000.0f);
  k.range(w, "max_step_s", c.max_step_s, 1e-4f, 1.0f);
  k.vec(w, "gravity", c.gravity, 1000.0f);
  k.vec(w, "wind", c.wind, 1000.0f);
  k.range(w, "drag", c.drag, 0.0f, 1000.0f);
  k.range(w, "damping", c.damping, 0.0f, 1000.0f);
  k.range(w, "max_speed", c.max_speed, 0.0f, 1000.0f);
  k.range(w, "stretch_compliance", c.stretch_compliance, 0.0f, 1.0f);
  k.range(w, "shear_compliance", c.shear_compliance, 0.0f, 1.0f);
  k.range(w, "bend_compliance", c.bend_compliance, 0.0f, 1.0f);
  k.range(w, "tether_compliance", c.tether_compliance, 0.0f, 1.0f);
  k.range(w, "tether_scale", c.tether_scale, 1.0f, 10.0f);
  k.range(w, "static_friction", c.static_friction, 0.0f, 10.0f);
  k.range(w, "kinetic_friction", c.kinetic_friction, 0.0f, 10.0f);
  k.range(w, "collision_margin_m", c.collision_margin_m, 0.0f, 0.05f);
  k.range(w, "contact_response", static_cast<float>(c.contact_response), 0.0f, 1.0f);
  k.range(w, "continuous_collision", static_cast<float>(c.continuous_collision), 0.0f, 1.0f);
  k.range(w, "linear_inertia", c.linear_inertia, 0.0f, 1.0f);
  k.range(w, "angular_inertia", c.angular_inertia, 0.0f, 1.0f);
  k.range(w, "blend_in_s", c.blend_in_s, 0.0f, 2.0f);
  k.range(w, "spring_stretch", c.spring_stretch, 0.0f, 1e6f);
  k.range(w, "spring_shear", c.spring_shear, 0.0f, 1e6f);
  k.range(w, "spring_bend", c.spring_bend, 0.0f, 1e6f);
  k.range(w, "spring_damping", c.spring_damping, 0.0f, 1e6f);
  k.range(w, "iterations", static_cast<float>(c.iterations), 1.0f, 64.0f);
  k.range(w, "strain_limit", c.strain_limit, 0.0f, 10.0f);
  k.range(w, "collision_stride", static_cast<float>(c.collision_stride), 0.0f, 8.0f);
  k.range(w, "strain_limit_passes", static_cast<float>(c.strain_limit_passes), 1.0f, 16.0f);
  if (drape_result r = k.done(fn)) return r;
  drape::GarmentSimParams p;
  p.substep_hz = c.substep_hz;
  p.max_substeps = static_cast<int>(c.max_substeps);
  p.max_step_s = c.max_step_s;
  p.xpbd.gravity = v3(c.gravity);
  p.xpbd.wind = v3(c.wind);
  p.xpbd.drag = c.drag;
  p.xpbd.damping = c.damping;
  p.xpbd.max_speed = c.max_speed;
  p.xpbd.stretch_compliance = c.stretch_compliance;
  p.xpbd.shear_compliance = c.shear_compliance;
  p.xpbd.bend_compliance = c.bend_compliance;
  p.xpbd.tether_compliance = c.tether_compliance;
  p.xpbd.tether_scale = c.tether_scale;
  p.xpbd.collision.static_friction = c.static_friction;
  p.xpbd.collision.kinetic_friction = c.kinetic_friction;
  p.xpbd.collision.response = static_cast<drape::ContactResponse>(c.contact_response);
  p.xpbd.collision.continuous = c.continuous_collision != 0;
  p.collision_margin_m = c.collision_margin_m;
  p.linear_inertia = c.linear_inertia;
  p.angular_inertia = c.angular_inertia;
  p.blend_in_s = c.blend_in_s;
  p.mass_spring.damping = c.damping;
  p.mass_spring.stretch_stiffness = c.spring_stretch;
  p.mass_spring.shear_stiffness = c.spring_shear;
  p.mass_spring.bend_stiffness = c.spring_bend;
  p.mass_spring.spring_damping = c.spring_damping;
  p.xpbd.iterations = static_cast<int>(c.iterations);
  p.xpbd.strain_limit = c.strain_limit;
  p.xpbd.collision_stride = static_cast<int>(c.collision_stride);
  p.xpbd.strain_limit_passes = static_cast<int>(c.strain_limit_passes);
  const std::string e = drape::validate(p);
  if (!e.empty()) return fail(DRAPE_ERROR_OUT_OF_RANGE, std::string(fn) + ": cloth params: " + e);
  out = p;
  return DRAPE_OK;
}

void fromSimParams(const drape::GarmentSimParams& p, drape_cloth_params& c) {
  const uint32_t size = c.struct_size;
  std::memset(&c, 0, sizeof(c));
  c.struct_size = size;
  c.substep_hz = p.substep_hz;
  c.max_substeps = static_cast<uint32_t>(p.max_substeps);
  c.max_step_s = p.max_step_s;
  c.gravity = c3(p.xpbd.gravity);
  c.wind = c3(p.xpbd.wind);
  c.drag = p.xpbd.drag;
  c.damping = p.xpbd.damping;
  c.max_speed = p.xpbd.max_speed;
  c.stretch_compliance = p.xpbd.stretch_compliance;
  c.shear_compliance = p.xpbd.shear_compliance;
  c.bend_compliance = p.xpbd.bend_compliance;
  c.tether_compliance = p.xpbd.tether_compliance;
  c.tether_scale = p.xpbd.tether_scale;
  c.static_friction = p.xpbd.collision.static_friction;
  c.kinetic_friction = p.xpbd.collision.kinetic_friction;
  c.collision_margin_m = p.collision_margin_m;
  c.contact_response = static_cast<int32_t>(p.xpbd.collision.response);
  c.continuous_collision = p.xpbd.collision.continuous ? 1u : 0u;
  c.linear_inertia = p.linear_inertia;
  c.angular_inertia = p.angular_inertia;
  c.blend_in_s = p.blend_in_s;
  c.spring_stretch = p.mass_spring.stretch_stiffness;
  c.spring_shear = p.mass_spring.shear_stiffness;
  c.spring_bend = p.mass_spring.bend_stiffness;
  c.spring_damping = p.mass_spring.spring_damping;
  c.iterations = static_cast<uint32_t>(p.xpbd.iterations);
  c.strain_limit = p.xpbd.strain_limit;
  c.collision_stride = static_cast<uint32_t>(p.xpbd.collision_stride);
  c.strain_limit_passes = static_cast<uint32_t>(p.xpbd.strain_limit_passes);
}

// A caller's drape_cloth_params, of the first layout (struct_size DRAPE_CLOTH_PARAMS_SIZE_V1,
// without collision_stride), the second (V2, without strain_limit_passes) or the current one: the
// fields its struct_size covers whole, the later ones' defaults. Nothing past the caller's
// struct_size is read.
drape_result readClothParams(const drape_cloth_params& in, drape_cloth_params& out) {
  if (drape_result r = checkStructSize(in.struct_size, DRAPE_CLOTH_PARAMS_SIZE_V1, "drape_cloth_params")) return r;
  drape_cloth_params_init(&out);
  std::memcpy(&out, &in, DRAPE_CLOTH_PARAMS_SIZE_V1);
  if (in.struct_size >= offsetof(drape_cloth_params, collision_stride) + sizeof(out.collision_stride))
    out.collision_stride = in.collision_stride;
  if (in.struct_size >= offsetof(drape_cloth_params, strain_limit_passes) + sizeof(out.strain_limit_passes))
    out.strain_limit_passes = in.strain_limit_passes;
  out.struct_size = sizeof(drape_cloth_params);
  return DRAPE_OK;
}

// Resolves the optional desc and cloth structs (NULL: defaults) and validates them.
drape_result readCommon(const char* fn, const drape_garment_desc* desc, const drape_cloth_params* cloth,
                        drape_garment_desc& d, drape::GarmentSimParams& sim) {
  drape_garment_desc_init(&d);
  if (desc) {
    if (drape_result r = checkStructSize(desc->struct_size, sizeof(drape_garment_desc), "drape_garment_desc")) return r;
    d = *desc;
  }
  Checker k;
  const char* w = "garment desc";
  k.range(w, "solver", static_cast<float>(d.solver), 0.0f, 1.0f);
  k.range(w, "area_density", d.area_density, 1e-6f, 10.0f);
  k.range(w, "max_tethers", static_cast<float>(d.max_tethers), 0.0f, 8.0f);
  k.range(w, "dress_time_s", d.dress_time_s, 0.0f, 10.0f);
  k.range(w, "cut", static_cast<float>(d.cut), 0.0f, 3.0f);
  if (drape_result r = k.done(fn)) return r;
  drape_cloth_params c;
  drape_cloth_params_init(&c);
  if (cloth) {
    if (drape_result r = readClothParams(*cloth, c)) return r;
  }
  return toSimParams(fn, c, sim);
}

drape_result toFitParams(const char* fn, const drape_mesh_fit* fit, drape::ObjFitParams& out) {
  drape_mesh_fit f;
  drape_mesh_fit_init(&f);
  if (fit) {
    if (drape_result r = checkStructSize(fit->struct_size, sizeof(drape_mesh_fit), "drape_mesh_fit")) return r;
    f = *fit;
  }
  Checker k;
  const char* w = "mesh fit";
  k.range(w, "unit_scale", f.unit_scale, 0.0f, 1000.0f);
  k.range(w, "facing", static_cast<float>(f.facing), 0.0f, 1.0f);
  k.range(w, "source_height_m", f.source_height_m, 0.8f, 2.5f);
  k.range(w, "source_weight_kg", f.source_weight_kg, 15.0f, 300.0f);
  k.range(w, "source_floor_y_m", f.source_floor_y_m, -100.0f, 100.0f);
  k.range(w, "source_axis_z_m", f.source_axis_z_m, -100.0f, 100.0f);
  k.range(w, "source_arm_down_deg", f.source_arm_down_deg, 0.0f, 90.0f);
  k.range(w, "source_elbow_flex_deg", f.source_elbow_flex_deg, 0.0f, 150.0f);
  k.range(w, "source_leg_spread_deg", f.source_leg_spread_deg, 0.0f, 45.0f);
  k.range(w, "blend_m", f.blend_m, 0.0f, 0.2f);
  k.reserved(w, f.reserved);
  if (drape_result r = k.done(fn)) return r;
  out.unit_scale = f.unit_scale;
  out.facing = static_cast<drape::ObjFacing>(f.facing);
  out.source_height_m = f.source_height_m;
  out.source_weight_kg = f.source_weight_kg;
  out.source_floor_y = f.source_floor_y_m;
  out.source_axis_z = f.source_axis_z_m;
  out.source_arm_down_deg = f.source_arm_down_deg;
  out.source_elbow_flex_deg = f.source_elbow_flex_deg;
  out.source_leg_spread_deg = f.source_leg_spread_deg;
  out.blend_m = f.blend_m;
  return DRAPE_OK;
}

drape::TopologyParams topologyFrom(const drape_garment_desc& d) {
  drape::TopologyParams tp;
  tp.area_density = d.area_density;
  tp.max_tethers_per_particle = static_cast<int>(d.max_tethers);
  return tp;
}

// Hands out a handle for a garment dressed on the context's rest body for `cut` (null: `err` says why).
drape_result adoptCreated(const char* fn, Context& ctx, Context::RestCut cut, std::unique_ptr<GarmentSim> g,
                          const std::string& err, drape_garment** out, bool shape_while_it_fits = false) {
  if (!g) return fail(DRAPE_ERROR_INVALID_ARGUMENT, std::string(fn) + ": " + err);
  GarmentSim* raw = g.get();
  void* token = registerHandle(HandleKind::Garment, raw);
  raw->api_token = token;
  raw->api_owner = &ctx;
  ctx.adoptGarment(std::move(g), cut, shape_while_it_fits);
  *out = static_cast<drape_garment*>(token);
  return DRAPE_OK;
}

// Dresses `mesh` on the context's rest body for the desc's cut and hands out a handle.
drape_result adopt(const char* fn, Context& ctx, const drape::GarmentMesh& mesh, const drape_garment_desc& d,
                   const drape::GarmentSimParams& sim, drape_garment** out, bool cut_from_dressed) {
  std::string err;
  const Context::RestCut cut = ctx.cutFor(d.cut, /*limbs_must_fit=*/false, /*template_kind=*/false);
  auto g = GarmentSim::create(mesh, topologyFrom(d), static_cast<drape::ClothSolverKind>(d.solver), sim,
                              d.dress_time_s, ctx.restBody(cut), ctx.restEllipsoids(cut), ctx.restEllipsoidGroups(cut),
                              err, cut_from_dressed);
  return adoptCreated(fn, ctx, cut, std::move(g), err, out);
}

drape_result addFitted(const char* fn, Context& ctx, const drape::ObjMesh& obj, const drape_mesh_fit* fit,
                       const drape_garment_desc& d, const drape::GarmentSimParams& sim, drape_garment** out) {
  drape::ObjFitParams fp;
  if (drape_result r = toFitParams(fn, fit, fp)) return r;
  drape::GarmentMesh mesh;
  std::string err;
  if (!drape::fitObjGarment(obj, fp, ctx.restBody(ctx.cutFor(d.cut, /*limbs_must_fit=*/false, /*template_kind=*/false)), mesh, err))
    return fail(DRAPE_ERROR_INVALID_ARGUMENT, std::string(fn) + ": " + err);
  return adopt(fn, ctx, mesh, d, sim, out, /*cut_from_dressed=*/true);
}

}  // namespace

// Called by drape_context_destroy before the context goes: its garments' handles die with it.
namespace drape::api {
void forgetGarments(Context& ctx) {
  for (size_t i = 0; i < ctx.garmentCount(); ++i) unregisterHandle(HandleKind::Garment, ctx.garment(i).api_token);
}
}  // namespace drape::api

extern "C" {

DRAPE_API drape_result DRAPE_CALL drape_garment_desc_init(drape_garment_desc* desc) {
  if (!desc) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_desc_init: desc is NULL");
  std::memset(desc, 0, sizeof(*desc));
  const drape::TopologyParams t;
  desc->struct_size = sizeof(drape_garment_desc);
  desc->solver = DRAPE_SOLVER_XPBD;
  desc->area_density = t.area_density;
  desc->max_tethers = static_cast<uint32_t>(t.max_tethers_per_particle);
  desc->dress_time_s = 0.5f;
  desc->cut = DRAPE_GARMENT_CUT_BY_KIND;
  return DRAPE_OK;
}

DRAPE_API drape_result DRAPE_CALL drape_garment_template_init(drape_garment_template* tmpl) {
  if (!tmpl) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_template_init: tmpl is NULL");
  std::memset(tmpl, 0, sizeof(*tmpl));
  const drape::GarmentTemplateParams t;
  tmpl->struct_size = sizeof(drape_garment_template);
  tmpl->kind = static_cast<int32_t>(t.kind);
  tmpl->particles = static_cast<uint32_t>(t.target_particles);
  tmpl->ease_m = t.ease_m;
  tmpl->length_scale = t.length_scale;
  return DRAPE_OK;
}

DRAPE_API drape_result DRAPE_CALL drape_cloth_params_init_sized(drape_cloth_params* params, uint32_t struct_size) {
  if (drape_result r = checkSizedInit("drape_cloth_params_init_sized", params, "params", struct_size,
                                      DRAPE_CLOTH_PARAMS_SIZE_V1, sizeof(drape_cloth_params)))
    return r;
  drape_cloth_params c;
  c.struct_size = struct_size;
  fromSimParams(drape::GarmentSimParams{}, c);
  std::memcpy(params, &c, struct_size);
  return DRAPE_OK;
}

// The header maps drape_cloth_params_init to the sized init with the caller's sizeof; this is the
// exported symbol hosts built before collision_stride call: the first layout's 128 bytes.
#undef drape_cloth_params_init
DRAPE_API drape_result DRAPE_CALL drape_cloth_params_init(drape_cloth_params* params) {
  if (!params) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_cloth_params_init: params is NULL");
  return drape_cloth_params_init_sized(params, DRAPE_CLOTH_PARAMS_SIZE_V1);
}

DRAPE_API drape_result DRAPE_CALL drape_mesh_fit_init(drape_mesh_fit* fit) {
  if (!fit) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_mesh_fit_init: fit is NULL");
  std::memset(fit, 0, sizeof(*fit));
  const drape::ObjFitParams p;
  fit->struct_size = sizeof(drape_mesh_fit);
  fit->unit_scale = p.unit_scale;
  fit->facing = static_cast<int32_t>(p.facing);
  fit->source_height_m = p.source_height_m;
  fit->source_weight_kg = p.source_weight_kg;
  fit->source_floor_y_m = p.source_floor_y;
  fit->source_axis_z_m = p.source_axis_z;
  fit->source_arm_down_deg = p.source_arm_down_deg;
  fit->source_elbow_flex_deg = p.source_elbow_flex_deg;
  fit->source_leg_spread_deg = p.source_leg_spread_deg;
  fit->blend_m = p.blend_m;
  return DRAPE_OK;
}

DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_template(drape_context* context,
                                                                     const drape_garment_desc* desc,
                                                                     const drape_garment_template* tmpl,
                                                                     const drape_cloth_params* cloth,
                                                                     drape_garment** out_garment) {
  static const char* fn = "drape_context_add_garment_template";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_add_garment_template", context);
    if (!out_garment) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": out_garment is NULL");
    drape_garment_desc d;
    drape::GarmentSimParams sim;
    if (drape_result r = readCommon(fn, desc, cloth, d, sim)) return r;
    drape_garment_template t;
    drape_garment_template_init(&t);
    if (tmpl) {
      if (drape_result r = checkStructSize(tmpl->struct_size, sizeof(drape_garment_template), "drape_garment_template")) return r;
      t = *tmpl;
    }
    Checker k;
    k.range("garment template", "kind", static_cast<float>(t.kind), 0.0f, 4.0f);
    k.range("garment template", "particles", static_cast<float>(t.particles), 200.0f, 200000.0f);
    k.range("garment template", "ease_m", t.ease_m, 0.002f, 0.1f);
    k.range("garment template", "length_scale", t.length_scale, 0.5f, 1.5f);
    k.reserved("garment template", t.reserved);
    if (drape_result r = k.done(fn)) return r;
    drape::GarmentTemplateParams tp;
    tp.kind = static_cast<drape::GarmentKind>(t.kind);
    tp.target_particles = static_cast<int>(t.particles);
    tp.ease_m = t.ease_m;
    tp.length_scale = t.length_scale;
    std::string err;
    const bool limbs = drape::garmentReachesLimbEnds(tp.kind);
    const Context::RestCut cut = ctx->cutFor(d.cut, limbs);
    auto g = GarmentSim::createTemplate(tp, topologyFrom(d), static_cast<drape::ClothSolverKind>(d.solver), sim,
                                        d.dress_time_s, ctx->restBody(cut), ctx->restEllipsoids(cut),
                                        ctx->restEllipsoidGroups(cut), err);
    return adoptCreated(fn, *ctx, cut, std::move(g), err, out_garment, ctx->cutFollowsShapeFit(d.cut, limbs));
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_obj_file(drape_context* context, const char* path,
                                                                     const drape_mesh_fit* fit,
                                                                     const drape_garment_desc* desc,
                                                                     const drape_cloth_params* cloth,
                                                                     drape_garment** out_garment) {
  static const char* fn = "drape_context_add_garment_obj_file";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_add_garment_obj_file", context);
    if (!path) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": path is NULL");
    if (!out_garment) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": out_garment is NULL");
    drape_garment_desc d;
    drape::GarmentSimParams sim;
    if (drape_result r = readCommon(fn, desc, cloth, d, sim)) return r;
    drape::ObjMesh obj;
    std::string err;
    bool io = false;
    if (!drape::readObjFile(path, obj, err, &io))
      return fail(io ? DRAPE_ERROR_IO : DRAPE_ERROR_PARSE, std::string(fn) + ": " + err);
    return addFitted(fn, *ctx, obj, fit, d, sim, out_garment);
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_obj_memory(drape_context* context, const void* data,
                                                                       size_t size, const drape_mesh_fit* fit,
                                                                       const drape_garment_desc* desc,
                                                                       const drape_cloth_params* cloth,
                                                                       drape_garment** out_garment) {
  static const char* fn = "drape_context_add_garment_obj_memory";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_add_garment_obj_memory", context);
    if (!data) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": data is NULL");
    if (!out_garment) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": out_garment is NULL");
    drape_garment_desc d;
    drape::GarmentSimParams sim;
    if (drape_result r = readCommon(fn, desc, cloth, d, sim)) return r;
    drape::ObjMesh obj;
    std::string err;
    if (!drape::parseObj(static_cast<const char*>(data), size, obj, err))
      return fail(DRAPE_ERROR_PARSE, std::string(fn) + ": " + err);
    return addFitted(fn, *ctx, obj, fit, d, sim, out_garment);
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_mesh(drape_context* context, const drape_vec3* positions,
                                                                 uint32_t vertex_count, const uint32_t* indices,
                                                                 uint32_t index_count, const drape_mesh_fit* fit,
                                                                 const drape_garment_desc* desc,
                                                                 const drape_cloth_params* cloth,
                                                                 drape_garment** out_garment) {
  static const char* fn = "drape_context_add_garment_mesh";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_add_garment_mesh", context);
    if (!positions || !indices) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": positions or indices is NULL");
    if (!out_garment) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": out_garment is NULL");
    if (vertex_count < 3 || index_count < 3 || index_count % 3 != 0)
      return fail(DRAPE_ERROR_INVALID_ARGUMENT, std::string(fn) + ": need >= 3 vertices and a positive multiple of 3 indices");
    drape_garment_desc d;
    drape::GarmentSimParams sim;
    if (drape_result r = readCommon(fn, desc, cloth, d, sim)) return r;
    drape::ObjMesh obj;
    obj.positions.resize(vertex_count);
    for (uint32_t i = 0; i < vertex_count; ++i) {
      const drape_vec3& p = positions[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return fail(DRAPE_ERROR_NONFINITE, std::string(fn) + ": vertex " + std::to_string(i) + " is not finite");
      obj.positions[i] = v3(p);
    }
    obj.indices.assign(indices, indices + index_count);
    for (uint32_t i = 0; i < index_count; ++i) {
      if (indices[i] >= vertex_count)
        return fail(DRAPE_ERROR_OUT_OF_RANGE, std::string(fn) + ": index " + std::to_string(i) + " = " +
                                                  std::to_string(indices[i]) + " is not below vertex_count");
    }
    return addFitted(fn, *ctx, obj, fit, d, sim, out_garment);
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_destroy(drape_garment* handle) {
  return guarded("drape_garment_destroy", [&]() -> drape_result {
    if (!handle) return DRAPE_OK;
    auto* g = static_cast<GarmentSim*>(unregisterHandle(HandleKind::Garment, handle));
    if (!g) return fail(DRAPE_ERROR_INVALID_HANDLE, "drape_garment_destroy: garment is not a live drape_garment");
    static_cast<Context*>(g->api_owner)->removeGarment(g);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_set_params(drape_garment* handle, const drape_cloth_params* params) {
  static const char* fn = "drape_garment_set_params";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_set_params", handle);
    if (!params) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": params is NULL");
    drape_cloth_params c;
    if (drape_result r = readClothParams(*params, c)) return r;
    drape::GarmentSimParams sim;
    if (drape_result r = toSimParams(fn, c, sim)) return r;
    std::string err;
    if (!garment->setParams(sim, err)) return fail(DRAPE_ERROR_OUT_OF_RANGE, std::string(fn) + ": " + err);
    // New parameters change how the cloth hangs: a sleeping garment steps again (adaptive.h).
    static_cast<Context*>(garment->api_owner)->wakeGarment(garment);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_get_params(drape_garment* handle, drape_cloth_params* out) {
  return guarded("drape_garment_get_params", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_get_params", handle);
    if (!out) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_get_params: out_params is NULL");
    if (drape_result r = checkStructSize(out->struct_size, DRAPE_CLOTH_PARAMS_SIZE_V1, "drape_cloth_params")) return r;
    drape_cloth_params c;
    c.struct_size = out->struct_size;
    fromSimParams(garment->params(), c);
    // A caller of the first layout gets its 128 bytes; nothing past its struct_size is written.
    std::memcpy(out, &c, std::min<size_t>(out->struct_size, sizeof(c)));
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_set_layer(drape_garment* handle, int32_t layer) {
  return guarded("drape_garment_set_layer", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_set_layer", handle);
    if (layer < 0 || layer > Context::kMaxGarmentLayer)
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_garment_set_layer: layer " + std::to_string(layer) +
                                                " is outside [0, " + std::to_string(Context::kMaxGarmentLayer) + "]");
    static_cast<Context*>(garment->api_owner)->setGarmentLayer(garment, layer);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_get_layer(drape_garment* handle, int32_t* out_layer) {
  return guarded("drape_garment_get_layer", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_get_layer", handle);
    if (!out_layer) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_get_layer: out_layer is NULL");
    *out_layer = static_cast<Context*>(garment->api_owner)->garmentLayer(garment);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_step(drape_context* context, float dt) {
  return guarded("drape_context_step", [&]() -> drape_result {
    DRAPE_CHECK_CONTEXT("drape_context_step", context);
    std::string err;
    if (drape_result r = ctx->step(dt, err)) return fail(r, "drape_context_step: " + err);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_get_mesh_size(drape_garment* handle, uint32_t* out_vertex_count,
                                                              uint32_t* out_index_count) {
  return guarded("drape_garment_get_mesh_size", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_get_mesh_size", handle);
    if (!out_vertex_count && !out_index_count)
      return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_get_mesh_size: both out pointers are NULL");
    if (out_vertex_count) *out_vertex_count = static_cast<uint32_t>(garment->particleCount());
    if (out_index_count) *out_index_count = static_cast<uint32_t>(garment->indices().size());
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_read_mesh(drape_garment* handle, drape_vec3* positions,
                                                          drape_vec3* normals, uint32_t vertex_capacity,
                                                          uint32_t* indices, uint32_t index_capacity) {
  static const char* fn = "drape_garment_read_mesh";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_read_mesh", handle);
    if (!positions && !normals && !indices)
      return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": positions, normals and indices are all NULL");
    const size_t n = garment->particleCount(), m = garment->indices().size();
    if ((positions || normals) && vertex_capacity < n)
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, std::string(fn) + ": vertex_capacity " + std::to_string(vertex_capacity) +
                                                    " < " + std::to_string(n));
    if (indices && index_capacity < m)
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, std::string(fn) + ": index_capacity " + std::to_string(index_capacity) +
                                                    " < " + std::to_string(m));
    // Computed before anything is written (the first call may throw bad_alloc).
    const std::vector<drape::Vec3>* nrm = normals ? &garment->normals() : nullptr;
    const Eigen::Vector4f* x = garment->positions();
    if (positions)
      for (size_t i = 0; i < n; ++i) positions[i] = drape_vec3{x[i].x(), x[i].y(), x[i].z()};
    if (normals)
      for (size_t i = 0; i < n; ++i) normals[i] = c3((*nrm)[i]);
    if (indices) std::copy(garment->indices().begin(), garment->indices().end(), indices);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_read_rest_positions(drape_garment* handle, drape_vec3* positions,
                                                                    uint32_t vertex_capacity) {
  static const char* fn = "drape_garment_read_rest_positions";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_read_rest_positions", handle);
    if (!positions) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": positions is NULL");
    const std::vector<drape::Vec3>& rest = garment->topology().rest_positions;
    if (vertex_capacity < rest.size())
      return fail(DRAPE_ERROR_BUFFER_TOO_SMALL, std::string(fn) + ": vertex_capacity " + std::to_string(vertex_capacity) +
                                                    " < " + std::to_string(rest.size()));
    for (size_t i = 0; i < rest.size(); ++i) positions[i] = c3(rest[i]);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_view_positions(drape_garment* handle, const float** out_xyzw,
                                                               uint32_t* out_vertex_count) {
  return guarded("drape_garment_view_positions", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_view_positions", handle);
    if (!out_xyzw) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_view_positions: out_xyzw is NULL");
    static_assert(sizeof(Eigen::Vector4f) == 4 * sizeof(float), "positions are packed float4");
    *out_xyzw = garment->positions()->data();
    if (out_vertex_count) *out_vertex_count = static_cast<uint32_t>(garment->particleCount());
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_get_stats(drape_garment* handle, drape_garment_stats* out) {
  return guarded("drape_garment_get_stats", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_get_stats", handle);
    if (!out) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_get_stats: out_stats is NULL");
    // The first version of the struct (up to device_upload_ms: 72 bytes) is still accepted: the
    // caller's struct_size says how many bytes are its own.
    constexpr uint32_t kFirstVersionSize = offsetof(drape_garment_stats, device_upload_ms);
    if (drape_result r = checkStructSize(out->struct_size, kFirstVersionSize, "drape_garment_stats")) return r;
    const drape::GarmentStepStats& s = garment->lastStep();
    drape_garment_stats o;
    std::memset(&o, 0, sizeof(o));
    o.struct_size = sizeof(o);
    o.particles = static_cast<uint32_t>(garment->particleCount());
    o.attached = static_cast<uint32_t>(garment->topology().pinned.size());
    o.substeps = static_cast<uint32_t>(s.substeps);
    o.blend_frames = static_cast<uint32_t>(s.blend_frames);
    o.contacts = s.collision.contacts;
    o.swept_catches = s.collision.swept_catches;
    o.escapes = s.collision.escapes;
    o.steps = garment->steps();
    o.teleport_reset = s.teleport_reset ? 1 : 0;
    o.nan_reset = s.nan_reset ? 1 : 0;
    o.refits = garment->refits();
    o.cut = static_cast<Context*>(garment->api_owner)->cutOf(*garment) == Context::kCutSkeleton
                ? static_cast<uint8_t>(DRAPE_GARMENT_FIT_SKELETON)
                : static_cast<uint8_t>(DRAPE_GARMENT_FIT_SHAPE);
    o.step_ms = s.total_ms;
    o.collide_ms = s.collide_ms;
    o.integrate_ms = s.total_ms - s.collide_ms;
    o.device_upload_ms = s.device.upload_ms;
    o.device_kernel_ms = s.device.kernel_ms;
    o.device_readback_ms = s.device.readback_ms;
    o.device_host_ms = s.device.host_ms;
    o.struct_size = std::min<uint32_t>(out->struct_size, sizeof(o));
    std::memcpy(out, &o, o.struct_size);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_garment_measure(drape_garment* handle, drape_garment_accuracy* out) {
  return guarded("drape_garment_measure", [&]() -> drape_result {
    DRAPE_CHECK_GARMENT("drape_garment_measure", handle);
    if (!out) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_garment_measure: out_accuracy is NULL");
    // The earlier versions of the struct (up to openings: 32 bytes; up to inside_body: 40) are still
    // accepted: the caller's struct_size says how many bytes are its own.
    constexpr uint32_t kFirstVersionSize = offsetof(drape_garment_accuracy, openings);
    if (drape_result r = checkStructSize(out->struct_size, kFirstVersionSize, "drape_garment_accuracy")) return r;
    const drape::GarmentAccuracy a = static_cast<Context*>(garment->api_owner)->measureGarment(*garment);
    drape_garment_accuracy o;
    std::memset(&o, 0, sizeof(o));
    o.struct_size = sizeof(o);
    o.proxy_inside = a.proxy_inside;
    o.max_stretch = a.stretch.max;
    o.p99_stretch = a.stretch.p99;
    o.mean_stretch = a.stretch.mean;
    o.body_penetration_p99_mm = a.body_penetration_p99_mm;
    o.body_penetration_max_mm = a.body_penetration_max_mm;
    o.deeper_than_2mm = a.deeper_than_2mm;
    o.openings = a.openings.tracked;
    o.openings_off = a.openings.off;
    o.inside_body = a.inside_body;
    o.struct_size = std::min<uint32_t>(out->struct_size, sizeof(o));
    std::memcpy(out, &o, o.struct_size);
    return DRAPE_OK;
  });
}

}  // extern "C"

static_assert(sizeof(drape_garment_desc) == 24, "drape_garment_desc layout");
static_assert(sizeof(drape_garment_template) == 24, "drape_garment_template layout");
static_assert(sizeof(drape_mesh_fit) == 48, "drape_mesh_fit layout");
static_assert(sizeof(drape_garment_stats) == 104, "drape_garment_stats layout");
static_assert(offsetof(drape_garment_stats, device_upload_ms) == 72, "drape_garment_stats: the first version's 72 bytes moved");
static_assert(sizeof(drape_garment_accuracy) == 44, "drape_garment_accuracy layout");
static_assert(offsetof(drape_garment_accuracy, openings) == 32, "drape_garment_accuracy: the first version's 32 bytes moved");
static_assert(offsetof(drape_garment_accuracy, inside_body) == 40, "drape_garment_accuracy: the second version's 40 bytes moved");
static_assert(sizeof(drape_cloth_params) == 136, "drape_cloth_params layout");
static_assert(offsetof(drape_cloth_params, strain_limit_passes) == DRAPE_CLOTH_PARAMS_SIZE_V2,
              "drape_cloth_params: the second version's 132 bytes moved");
static_assert(offsetof(drape_cloth_params, collision_stride) == DRAPE_CLOTH_PARAMS_SIZE_V1,
              "drape_cloth_params: the first version's 128 bytes moved");
