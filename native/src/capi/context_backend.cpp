// Context's backend choice (docs/opencl.md): which garments step on an OpenCL device, the shared
// OpenCL runtimes, and the fallback to the CPU with its reason.
#include "capi/context.h"

#if DRAPE_HAVE_OPENCL
#include "backends/opencl/cl_garment_solver.h"
#include "backends/opencl/cl_runtime.h"
#endif

#include <cstring>
#include <map>
#include <mutex>
#include <tuple>

namespace drape {

struct Context::Backend {
  drape_backend_desc desc{};
#if DRAPE_HAVE_OPENCL
  std::shared_ptr<ClRuntime> runtime;
#endif
  std::string reason;  // why OpenCL is not (fully) used
};

namespace {

#if DRAPE_HAVE_OPENCL
// Contexts asking for the same device share one runtime (one program build, one queue): several
// people in one process cost one PoCL compile. Weak: the runtime goes with its last context.
std::shared_ptr<ClRuntime> sharedRuntime(const drape_backend_desc& d, std::string& err) {
  using Key = std::tuple<int, int, bool, void*, void*>;
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<ClRuntime>> cache;
  const Key key{d.platform_index, d.device_index, d.prefer_gpu != 0, d.host_cl_context, d.host_cl_queue};
  std::lock_guard<std::mutex> lock(mutex);
  if (auto rt = cache[key].lock()) return rt;
  ClChoice c;
  c.platform = d.platform_index;
  c.device = d.device_index;
  c.prefer_gpu = d.prefer_gpu != 0;
  c.host_context = d.host_cl_context;
  c.host_queue = d.host_cl_queue;
  std::shared_ptr<ClRuntime> rt = ClRuntime::create(c, err);
  if (rt) cache[key] = rt;
  return rt;
}
#endif


}  // namespace

drape_result Context::setBackend(const drape_backend_desc& desc, std::string& err) {
  auto next = std::make_shared<Backend>();
  next->desc = desc;
  if (desc.backend != DRAPE_BACKEND_CPU) {
#if DRAPE_HAVE_OPENCL
    std::string why;
    next->runtime = sharedRuntime(desc, why);
    if (!next->runtime) next->reason = why;
#else
    next->reason = "this build of Drape has no OpenCL backend (configured without an OpenCL SDK)";
#endif
  }
  backend_ = next;
  for (auto& g : garments_) applyBackend(*g);
  (void)err;
  return DRAPE_OK;
}

void Context::applyBackend(GarmentSim& g) {
  if (!backend_) return;  // never chosen: the CPU, as created
  std::string err;
  Backend& b = *backend_;
#if DRAPE_HAVE_OPENCL
  const bool want_cl = b.desc.backend == DRAPE_BACKEND_OPENCL ||
                       (b.desc.backend == DRAPE_BACKEND_AUTO && g.particleCount() >= b.desc.opencl_min_particles);
  if (want_cl && b.runtime && g.solver() == ClothSolverKind::Xpbd) {
    if (g.backend() == GarmentBackend::OpenCl || g.replaceSolver(clGarmentSolverFactory(b.runtime), err)) return;
    b.reason = "a garment could not move to the OpenCL device: " + err;
  } else if (want_cl && b.runtime) {
    b.reason = "the mass-spring solver runs on the CPU only";
  }
#endif
  if (!g.useCpuSolver(err) && b.reason.empty()) b.reason = "moving a garment back to the CPU failed: " + err;
}

void Context::runStagedFrames(const std::vector<GarmentSim*>& garments) {
#if DRAPE_HAVE_OPENCL
  runStagedClFrames(garments);
#else
  (void)garments;  // nothing is staged without a device solver
#endif
}

void Context::checkDeviceFailures() {
  for (auto& g : garments_) {
    std::string why;
    if (!g->deviceFailed(&why)) continue;
    // The device failed mid-run (lost, out of resources): this garment and the later ones go to
    // the CPU; its last good state carries over.
    std::string err;
    g->useCpuSolver(err);
    if (backend_) {
      backend_->reason = "the OpenCL device failed: " + why;
#if DRAPE_HAVE_OPENCL
      backend_->runtime.reset();
#endif
    }
  }
}

void Context::backendInfo(drape_backend_info& o) {
  std::memset(&o, 0, sizeof(o));
  infoDevice_.clear();
  infoPlatform_.clear();
  infoReason_.clear();
  o.struct_size = sizeof(o);
  o.requested = backend_ ? backend_->desc.backend : DRAPE_BACKEND_CPU;
  for (const auto& g : garments_) {
    if (g->backend() == GarmentBackend::OpenCl) ++o.opencl_garments;
    else ++o.cpu_garments;
  }
  o.active = o.opencl_garments > 0 ? DRAPE_BACKEND_OPENCL : DRAPE_BACKEND_CPU;
  o.device_name = infoDevice_.c_str();
  o.platform_name = infoPlatform_.c_str();
  o.fallback_reason = infoReason_.c_str();
  if (!backend_) return;
#if DRAPE_HAVE_OPENCL
  if (backend_->runtime) {
    infoDevice_ = backend_->runtime->deviceName();
    infoPlatform_ = backend_->runtime->platformName();
    // An OpenCL request with a working device and no garment yet counts as OpenCL.
    if (garments_.empty() && backend_->desc.backend == DRAPE_BACKEND_OPENCL) o.active = DRAPE_BACKEND_OPENCL;
  }
#endif
  infoReason_ = backend_->reason;
  o.device_name = infoDevice_.c_str();  // re-read: the strings changed
  o.platform_name = infoPlatform_.c_str();
  o.fallback_reason = infoReason_.c_str();
}

}  // namespace drape
