// OpenCL device choice and the program: platform/device enumeration, the choice (prefer a GPU,
// or the host's indices, or the host's own cl_context + cl_command_queue), and the program
// built once per runtime with -D sizes. A failure anywhere returns null with the reason (the
// build log included), which the caller reports as its fallback reason. docs/opencl.md.
#pragma once

#include "backends/opencl/cl_sources.h"

#include <CL/cl.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace drape {

class ClFrameBatch;

// Releases a buffer the caller owns (if any) and clears the handle, so a second call is harmless.
inline void release(cl_mem& m) {
  if (m) clReleaseMemObject(m);
  m = nullptr;
}

struct ClDeviceDesc {
  int platform = 0, device = 0;  // indices as enumerated
  std::string platform_name, device_name;
  bool gpu = false;
  uint64_t global_mem = 0, local_mem = 0;
  unsigned compute_units = 0;
};

// Every device of every platform, in enumeration order. Empty with `err` when there is no
// platform (no ICD installed) or enumeration fails.
std::vector<ClDeviceDesc> listClDevices(std::string& err);

struct ClChoice {
  int platform = -1, device = -1;  // -1: choose (a GPU first when prefer_gpu, else the first)
  bool prefer_gpu = true;
  void* host_context = nullptr;  // cl_context and cl_command_queue of the host: both or neither
  void* host_queue = nullptr;
  // Internal hooks (tests): appended to the build options / the program source.
  std::string extra_options, extra_source;
};

const char* clErrorName(cl_int code);

class ClRuntime {
 public:
  // Null with `err` on failure (no platform or device, bad indices, context or queue creation,
  // the program's build with its log).
  static std::shared_ptr<ClRuntime> create(const ClChoice& choice, std::string& err);
  ~ClRuntime();
  ClRuntime(const ClRuntime&) = delete;
  ClRuntime& operator=(const ClRuntime&) = delete;

  cl_context context() const { return context_; }
  cl_command_queue queue() const { return queue_; }
  cl_device_id device() const { return device_; }
  cl_program program() const { return program_; }
  const std::string& deviceName() const { return device_name_; }
  const std::string& platformName() const { return platform_name_; }
  bool profiling() const { return profiling_; }
  // Particles one work-group keeps in __local memory (DRAPE_CL_MAX_LOCAL_PARTICLES).
  size_t localParticles() const { return local_particles_; }
  // A GPU (CL_DEVICE_TYPE_GPU), not a CPU or accelerator device such as PoCL's.
  bool isGpu() const { return gpu_; }
  // The largest garment the automatic path runs as one work-group frame (cl_xpbd_solver.h,
  // ClXpbdSolver::Path): what fits in __local memory, at most kWorkGroupMaxParticles, and on a GPU
  // at most kGpuWorkGroupMaxParticles. One work-group runs on one of a GPU's compute units, so
  // its frame grows with the garment, while the per-phase launches spread over all of them for a
  // launch cost that hardly depends on the size. On an H100 (docs/opencl.md, "Fifth lease",
  // BM_BackendGarmentFrame with collision, medians of 5) the work-group frame took 1.45 ms at 885
  // particles against 1.73 for the phases, and 2.23 against 1.61 at 1 810; the lines cross near
  // 1 100-1 300 (two runs). On PoCL (the CPU as the device) the phases only win from ~7 800 particles: 4 096 there.
  static constexpr size_t kWorkGroupMaxParticles = 4096;
  static constexpr size_t kGpuWorkGroupMaxParticles = 1200;
  size_t workGroupMaxParticles() const { return work_group_max_particles_; }
  size_t workGroup() const { return work_group_; }
  double buildMs() const { return build_ms_; }

  // Kernel launches enqueued on this runtime's queue since it was created (every launch site
  // counts itself): tests check that a batched frame costs the same launches for 1 or N garments.
  uint64_t launchCount() const { return launches_.load(); }
  void countLaunches(uint64_t n = 1) {
    launches_ += n;
    processLaunches() += n;
  }
  // Launches on every runtime of the process (tests reach contexts' runtimes only through this).
  static uint64_t processLaunchCount() { return processLaunches().load(); }
  // The frame batcher of this runtime (cl_frame_batch.h), made on first use; its buffers grow to
  // the largest batch seen.
  ClFrameBatch& frameBatch();

 private:
  ClRuntime() = default;
  bool build(const ClChoice& choice, std::string& err);
  static std::atomic<uint64_t>& processLaunches();

  cl_context context_ = nullptr;
  cl_command_queue queue_ = nullptr;
  cl_device_id device_ = nullptr;
  cl_program program_ = nullptr;
  bool profiling_ = false;
  std::string device_name_, platform_name_;
  size_t local_particles_ = 1, work_group_ = 64, work_group_max_particles_ = 1;
  bool gpu_ = false;
  double build_ms_ = 0.0;
  std::atomic<uint64_t> launches_{0};
  std::mutex batch_mutex_;
  std::unique_ptr<ClFrameBatch> batch_;
};

}  // namespace drape
