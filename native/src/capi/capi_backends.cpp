// C entry points of the Backends section of drape.h (docs/opencl.md).
#include "capi/api_support.h"
#include "capi/context.h"

#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_runtime.h"
#endif

#include <cstring>
#include <mutex>
#include <set>
#include <string>
#include <vector>

using drape::Context;
using drape::api::checkStructSize;
using drape::api::fail;
using drape::api::guarded;

#if DRAPE_HAVE_OPENCL
namespace {
// Device names handed out by drape_opencl_device_get live until the process ends: each distinct
// string is kept once (a handful per machine).
const char* intern(const std::string& s) {
  static std::mutex mutex;
  static std::set<std::string> names;
  std::lock_guard<std::mutex> lock(mutex);
  return names.insert(s).first->c_str();
}
}  // namespace
#endif

static_assert(sizeof(drape_backend_desc) == 24 + 2 * sizeof(void*), "drape_backend_desc layout");
static_assert(sizeof(drape_backend_info) == 24 + 3 * sizeof(void*), "drape_backend_info layout");
static_assert(sizeof(drape_opencl_device) == 40 + 2 * sizeof(void*), "drape_opencl_device layout");

DRAPE_API drape_result DRAPE_CALL drape_backend_desc_init(drape_backend_desc* desc) {
  if (!desc) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_backend_desc_init: desc is NULL");
  std::memset(desc, 0, sizeof(*desc));
  desc->struct_size = sizeof(drape_backend_desc);
  desc->backend = DRAPE_BACKEND_CPU;
  desc->platform_index = -1;
  desc->device_index = -1;
  desc->prefer_gpu = 1;
  desc->opencl_min_particles = 2000;
  return DRAPE_OK;
}

DRAPE_API drape_result DRAPE_CALL drape_context_set_backend(drape_context* context, const drape_backend_desc* desc) {
  return guarded("drape_context_set_backend", [&]() -> drape_result {
    DRAPE_RESOLVE_CONTEXT(ctx, "drape_context_set_backend", context);
    if (!desc) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_set_backend: desc is NULL");
    if (drape_result r = checkStructSize(desc->struct_size, sizeof(drape_backend_desc), "drape_backend_desc")) return r;
    const drape_backend_desc& d = *desc;
    if (d.backend != DRAPE_BACKEND_CPU && d.backend != DRAPE_BACKEND_OPENCL && d.backend != DRAPE_BACKEND_AUTO)
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_context_set_backend: backend = " + std::to_string(d.backend) +
                                                " is not DRAPE_BACKEND_CPU (0), _OPENCL (1) or _AUTO (2)");
    if (d.platform_index < -1 || d.platform_index > 255 || d.device_index < -1 || d.device_index > 255)
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_context_set_backend: platform_index and device_index must be in [-1, 255]");
    if (d.prefer_gpu > 1) return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_context_set_backend: prefer_gpu must be 0 or 1");
    if (d.opencl_min_particles > 100000000u)
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_context_set_backend: opencl_min_particles must be at most 1e8");
    if ((d.host_cl_context == nullptr) != (d.host_cl_queue == nullptr))
      return fail(DRAPE_ERROR_INVALID_ARGUMENT,
                  "drape_context_set_backend: host_cl_context and host_cl_queue must be given together");
    std::string err;
    if (drape_result r = ctx->setBackend(d, err)) return fail(r, "drape_context_set_backend: " + err);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_context_get_backend_info(drape_context* context, drape_backend_info* out) {
  return guarded("drape_context_get_backend_info", [&]() -> drape_result {
    DRAPE_RESOLVE_CONTEXT(ctx, "drape_context_get_backend_info", context);
    if (!out) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_context_get_backend_info: out_info is NULL");
    if (drape_result r = checkStructSize(out->struct_size, sizeof(drape_backend_info), "drape_backend_info")) return r;
    ctx->backendInfo(*out);
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_opencl_device_count(uint32_t* out_count) {
  return guarded("drape_opencl_device_count", [&]() -> drape_result {
    if (!out_count) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_opencl_device_count: out_count is NULL");
#if DRAPE_HAVE_OPENCL
    std::string err;
    *out_count = static_cast<uint32_t>(drape::listClDevices(err).size());
#else
    *out_count = 0;
#endif
    return DRAPE_OK;
  });
}

DRAPE_API drape_result DRAPE_CALL drape_opencl_device_get(uint32_t index, drape_opencl_device* out) {
  return guarded("drape_opencl_device_get", [&]() -> drape_result {
    if (!out) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_opencl_device_get: out_device is NULL");
    if (drape_result r = checkStructSize(out->struct_size, sizeof(drape_opencl_device), "drape_opencl_device")) return r;
#if DRAPE_HAVE_OPENCL
    std::string err;
    const auto devices = drape::listClDevices(err);
    if (index >= devices.size())
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_opencl_device_get: index " + std::to_string(index) + " >= " +
                                                std::to_string(devices.size()) + " device(s)");
    const drape::ClDeviceDesc& d = devices[index];
    drape_opencl_device o;
    std::memset(&o, 0, sizeof(o));
    o.struct_size = sizeof(o);
    o.platform_index = d.platform;
    o.device_index = d.device;
    o.is_gpu = d.gpu ? 1 : 0;
    o.global_mem_bytes = d.global_mem;
    o.local_mem_bytes = d.local_mem;
    o.compute_units = d.compute_units;
    o.platform_name = intern(d.platform_name);
    o.device_name = intern(d.device_name);
    *out = o;
    return DRAPE_OK;
#else
    (void)index;
    return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_opencl_device_get: this build has no OpenCL backend (0 devices)");
#endif
  });
}

DRAPE_API drape_result DRAPE_CALL drape_step_contexts(drape_context* const* contexts, uint32_t count, float dt) {
  return guarded("drape_step_contexts", [&]() -> drape_result {
    if (!contexts) return fail(DRAPE_ERROR_NULL_ARGUMENT, "drape_step_contexts: contexts is NULL");
    if (count == 0 || count > DRAPE_MAX_STEP_CONTEXTS)
      return fail(DRAPE_ERROR_OUT_OF_RANGE, "drape_step_contexts: count = " + std::to_string(count) +
                                                " is outside [1, " + std::to_string(DRAPE_MAX_STEP_CONTEXTS) + "]");
    std::vector<Context*> resolved(count);
    for (uint32_t i = 0; i < count; ++i) {
      const std::string at = "drape_step_contexts: contexts[" + std::to_string(i) + "]";
      if (!contexts[i]) return fail(DRAPE_ERROR_NULL_ARGUMENT, at + " is NULL");
      resolved[i] = static_cast<Context*>(
          drape::api::resolveHandle(drape::api::HandleKind::Context, contexts[i]));
      if (!resolved[i])
        return fail(DRAPE_ERROR_INVALID_HANDLE, at + " is not a live drape_context (destroyed or never created)");
      for (uint32_t j = 0; j < i; ++j)
        if (resolved[j] == resolved[i])
          return fail(DRAPE_ERROR_INVALID_ARGUMENT,
                      at + " repeats contexts[" + std::to_string(j) + "] (each context steps once)");
    }
    std::string err;
    if (drape_result r = Context::stepContexts(resolved.data(), resolved.size(), dt, err))
      return fail(r, "drape_step_contexts: " + err);
    return DRAPE_OK;
  });
}
