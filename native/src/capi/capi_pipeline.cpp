// C entry points of the adaptive pipeline: options, wake, skip statistics (capi/adaptive.h).
#include "capi/api_support.h"
#include "capi/context.h"

#include <cstring>

using drape::Context;
using namespace drape::api;

namespace {

drape_result toOptions(const char* fn, const drape_pipeline_options& in, drape::PipelineOptions& out) {
  const uint32_t flags[3] = {in.cull_proxies, in.stages_on_demand, in.sleep};
  const char* names[3] = {"cull_proxies", "stages_on_demand", "sleep"};
  for (int i = 0; i < 3; ++i)
    if (flags[i] > 1)
      return fail(DRAPE_ERROR_OUT_OF_RANGE, std::string(fn) + ": " + names[i] + " = " + std::to_string(flags[i]) +
                                                " is not 0 or 1");
  if (in.reserved != 0) return fail(DRAPE_ERROR_INVALID_ARGUMENT, std::string(fn) + ": reserved must be 0");
  drape::PipelineOptions o;
  o.cull_proxies = in.cull_proxies != 0;
  o.stages_on_demand = in.stages_on_demand != 0;
  o.sleep = in.sleep != 0;
  o.sleep_delay_s = in.sleep_delay_s;
  o.sleep_distance_m = in.sleep_distance_m;
  o.sleep_speed_m_s = in.sleep_speed_m_s;
  o.reach_margin_m = in.reach_margin_m;
  bool nonfinite = false;
  const std::string err = drape::validate(o, &nonfinite);
  if (!err.empty())
    return fail(nonfinite ? DRAPE_ERROR_NONFINITE : DRAPE_ERROR_OUT_OF_RANGE, std::string(fn) + ": " + err);
  out = o;
  return DRAPE_OK;
}

void fromOptions(const drape::PipelineOptions& o, drape_pipeline_options& out) {
  std::memset(&out, 0, sizeof(out));
  out.struct_size = sizeof(out);
  out.cull_proxies = o.cull_proxies ? 1u : 0u;
  out.stages_on_demand = o.stages_on_demand ? 1u : 0u;
  out.sleep = o.sleep ? 1u : 0u;
  out.sleep_delay_s = o.sleep_delay_s;
  out.sleep_distance_m = o.sleep_distance_m;
  out.sleep_speed_m_s = o.sleep_speed_m_s;
  out.reach_margin_m = o.reach_margin_m;
}

}  // namespace

extern "C" {

DRAPE_API drape_result DRAPE_CALL drape_pipeline_options_init(drape_pipeline_options* options) {
  if (!options) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_pipeline_options_init: options is NULL");
  fromOptions(drape::PipelineOptions{}, *options);
  return DRAPE_OK;
}

DRAPE_API drape_result DRAPE_CALL drape_context_set_pipeline_options(drape_context* context,
                                                                     const drape_pipeline_options* options) {
  static const char* fn = "drape_context_set_pipeline_options";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_RESOLVE_CONTEXT(self, "drape_context_set_pipeline_options", context);
    if (!options) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": options is NULL");
    if (drape_result r = checkStructSize(options->struct_size, sizeof(drape_pipeline_options), "drape_pipeline_options"))
      return r;
    drape::PipelineOptions o;
    if (drape_result r = toOptions(fn, *options, o)) return r;
    self->setPipelineOptions(o);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_pipeline_options(drape_context* context,
                                                                     drape_pipeline_options* out_options) {
  static const char* fn = "drape_context_get_pipeline_options";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_RESOLVE_CONTEXT(self, "drape_context_get_pipeline_options", context);
    if (!out_options) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": out_options is NULL");
    if (drape_result r =
            checkStructSize(out_options->struct_size, sizeof(drape_pipeline_options), "drape_pipeline_options"))
      return r;
    drape_pipeline_options o;
    fromOptions(self->pipelineOptions(), o);
    *out_options = o;
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_wake(drape_context* context) {
  return guarded("drape_context_wake", [&]() -> drape_result {
    DRAPE_RESOLVE_CONTEXT(self, "drape_context_wake", context);
    self->wakeAll();
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_skip_stats(drape_context* context, drape_skip_stats* out_stats) {
  static const char* fn = "drape_context_get_skip_stats";
  return guarded(fn, [&]() -> drape_result {
    DRAPE_RESOLVE_CONTEXT(self, "drape_context_get_skip_stats", context);
    if (!out_stats) return fail(DRAPE_ERROR_NULL_ARGUMENT, std::string(fn) + ": out_stats is NULL");
    if (drape_result r = checkStructSize(out_stats->struct_size, sizeof(drape_skip_stats), "drape_skip_stats"))
      return r;
    const drape::SkipCounters c = self->skipCounters();
    drape_skip_stats s;
    std::memset(&s, 0, sizeof(s));
    s.struct_size = sizeof(s);
    s.proxies_available = c.proxies_available;
    s.proxies_built = c.proxies_built;
    s.stages_skipped_last = c.stages_skipped_last;
    s.garments = c.garments;
    s.garments_asleep = c.garments_asleep;
    s.updates = c.updates;
    s.stages_skipped = c.stages_skipped;
    s.proxies_skipped = c.proxies_skipped;
    s.steps = c.steps;
    s.frames_slept = c.frames_slept;
    s.garment_steps_slept = c.garment_steps_slept;
    *out_stats = s;
    return DRAPE_OK;
  });
}

}  // extern "C"

// Layout guarantees the C# bindings rely on.
static_assert(sizeof(drape_pipeline_options) == 36, "drape_pipeline_options layout");
static_assert(sizeof(drape_skip_stats) == 72, "drape_skip_stats layout");
static_assert(static_cast<uint32_t>(drape::kStageBodyMesh) == DRAPE_STAGE_BODY_MESH &&
                  static_cast<uint32_t>(drape::kStageBodyNormals) == DRAPE_STAGE_BODY_NORMALS &&
                  static_cast<uint32_t>(drape::kStageProxies) == DRAPE_STAGE_PROXIES &&
                  static_cast<uint32_t>(drape::kStageCloth) == DRAPE_STAGE_CLOTH,
              "stage bits match the C ABI");
