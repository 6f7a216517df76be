#include "backends/opencl/cl_runtime.h"

#include "backends/opencl/cl_frame_batch.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>

namespace drape {
namespace {

std::string deviceString(cl_device_id d, cl_device_info what) {
  size_t size = 0;
  if (clGetDeviceInfo(d, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return {};
  std::string s(size, '\0');
  if (clGetDeviceInfo(d, what, size, &s[0], nullptr) != CL_SUCCESS) return {};
  s.resize(std::strlen(s.c_str()));
  return s;
}

std::string platformString(cl_platform_id p, cl_platform_info what) {
  size_t size = 0;
  if (clGetPlatformInfo(p, what, 0, nullptr, &size) != CL_SUCCESS || size == 0) return {};
  std::string s(size, '\0');
  if (clGetPlatformInfo(p, what, size, &s[0], nullptr) != CL_SUCCESS) return {};
  s.resize(std::strlen(s.c_str()));
  return s;
}

template <class T>
T deviceValue(cl_device_id d, cl_device_info what) {
  T v{};
  if (clGetDeviceInfo(d, what, sizeof(T), &v, nullptr) != CL_SUCCESS) return T{};
  return v;
}

bool isGpuDevice(cl_device_id d) {
  return (deviceValue<cl_device_type>(d, CL_DEVICE_TYPE) & CL_DEVICE_TYPE_GPU) != 0;
}

std::vector<cl_platform_id> platforms(std::string& err) {
  cl_uint n = 0;
  const cl_int rc = clGetPlatformIDs(0, nullptr, &n);
  if (rc != CL_SUCCESS || n == 0) {
    err = std::string("no OpenCL platform (clGetPlatformIDs: ") +
          (rc == CL_SUCCESS ? "0 platforms" : clErrorName(rc)) + ")";
    return {};
  }
  std::vector<cl_platform_id> ids(n);
  clGetPlatformIDs(n, ids.data(), nullptr);
  return ids;
}

std::vector<cl_device_id> devicesOf(cl_platform_id p) {
  cl_uint n = 0;
  if (clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, 0, nullptr, &n) != CL_SUCCESS || n == 0) return {};
  std::vector<cl_device_id> ids(n);
  clGetDeviceIDs(p, CL_DEVICE_TYPE_ALL, n, ids.data(), nullptr);
  return ids;
}

}  // namespace

const char* clErrorName(cl_int code) {
  switch (code) {
    case CL_SUCCESS: return "CL_SUCCESS";
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_COMPILER_NOT_AVAILABLE: return "CL_COMPILER_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_PLATFORM: return "CL_INVALID_PLATFORM";
    case CL_INVALID_DEVICE: return "CL_INVALID_DEVICE";
    case CL_INVALID_CONTEXT: return "CL_INVALID_CONTEXT";
    case CL_INVALID_COMMAND_QUEUE: return "CL_INVALID_COMMAND_QUEUE";
    case CL_INVALID_MEM_OBJECT: return "CL_INVALID_MEM_OBJECT";
    case CL_INVALID_BUILD_OPTIONS: return "CL_INVALID_BUILD_OPTIONS";
    case CL_INVALID_PROGRAM: return "CL_INVALID_PROGRAM";
    case CL_INVALID_PROGRAM_EXECUTABLE: return "CL_INVALID_PROGRAM_EXECUTABLE";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_ARG_INDEX: return "CL_INVALID_ARG_INDEX";
    case CL_INVALID_ARG_VALUE: return "CL_INVALID_ARG_VALUE";
    case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_WORK_ITEM_SIZE: return "CL_INVALID_WORK_ITEM_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_EVENT: return "CL_INVALID_EVENT";
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR (no OpenCL driver installed)";
    default: return "CL error";
  }
}

std::vector<ClDeviceDesc> listClDevices(std::string& err) {
  std::vector<ClDeviceDesc> out;
  const std::vector<cl_platform_id> ps = platforms(err);
  for (size_t p = 0; p < ps.size(); ++p) {
    const std::vector<cl_device_id> ds = devicesOf(ps[p]);
    for (size_t d = 0; d < ds.size(); ++d) {
      ClDeviceDesc desc;
      desc.platform = static_cast<int>(p);
      desc.device = static_cast<int>(d);
      desc.platform_name = platformString(ps[p], CL_PLATFORM_NAME);
      desc.device_name = deviceString(ds[d], CL_DEVICE_NAME);
      desc.gpu = isGpuDevice(ds[d]);
      desc.global_mem = deviceValue<cl_ulong>(ds[d], CL_DEVICE_GLOBAL_MEM_SIZE);
      desc.local_mem = deviceValue<cl_ulong>(ds[d], CL_DEVICE_LOCAL_MEM_SIZE);
      desc.compute_units = deviceValue<cl_uint>(ds[d], CL_DEVICE_MAX_COMPUTE_UNITS);
      out.push_back(std::move(desc));
    }
  }
  return out;
}

std::shared_ptr<ClRuntime> ClRuntime::create(const ClChoice& choice, std::string& err) {
  std::shared_ptr<ClRuntime> rt(new ClRuntime());
  if (!rt->build(choice, err)) return nullptr;
  return rt;
}

ClRuntime::~ClRuntime() {
  batch_.reset();  // its kernel and buffers before the program and context they belong to
  if (program_) clReleaseProgram(program_);
  // Ours, or the host's that build() retained: either way one reference to release.
  if (queue_) clReleaseCommandQueue(queue_);
  if (context_) clReleaseContext(context_);
}

std::atomic<uint64_t>& ClRuntime::processLaunches() {
  static std::atomic<uint64_t> launches{0};
  return launches;
}

ClFrameBatch& ClRuntime::frameBatch() {
  std::lock_guard<std::mutex> lock(batch_mutex_);
  if (!batch_) batch_ = std::make_unique<ClFrameBatch>(*this);
  return *batch_;
}

bool ClRuntime::build(const ClChoice& choice, std::string& err) {
  cl_int rc = CL_SUCCESS;
  if ((choice.host_context == nullptr) != (choice.host_queue == nullptr)) {
    err = "host_cl_context and host_cl_queue must be given together";
    return false;
  }
  if (choice.host_context) {
    // The host's context and queue: the device is the queue's.
    context_ = static_cast<cl_context>(choice.host_context);
    queue_ = static_cast<cl_command_queue>(choice.host_queue);
    if ((rc = clGetCommandQueueInfo(queue_, CL_QUEUE_DEVICE, sizeof(device_), &device_, nullptr)) != CL_SUCCESS) {
      err = std::string("the host's command queue is not valid (") + clErrorName(rc) + ")";
      context_ = nullptr;
      queue_ = nullptr;
      return false;
    }
    cl_context queue_context = nullptr;
    clGetCommandQueueInfo(queue_, CL_QUEUE_CONTEXT, sizeof(queue_context), &queue_context, nullptr);
    if (queue_context != context_) {
      err = "the host's command queue does not belong to the host's context";
      context_ = nullptr;
      queue_ = nullptr;
      return false;
    }
    clRetainContext(context_);
    clRetainCommandQueue(queue_);
    cl_command_queue_properties props = 0;
    clGetCommandQueueInfo(queue_, CL_QUEUE_PROPERTIES, sizeof(props), &props, nullptr);
    profiling_ = (props & CL_QUEUE_PROFILING_ENABLE) != 0;
    cl_platform_id platform = nullptr;
    clGetDeviceInfo(device_, CL_DEVICE_PLATFORM, sizeof(platform), &platform, nullptr);
    platform_name_ = platform ? platformString(platform, CL_PLATFORM_NAME) : std::string();
  } else {
    const std::vector<cl_platform_id> ps = platforms(err);
    if (ps.empty()) return false;
    if (choice.platform >= static_cast<int>(ps.size()) || choice.platform < -1) {
      err = "OpenCL platform index " + std::to_string(choice.platform) + " does not exist (" +
            std::to_string(ps.size()) + " platform(s))";
      return false;
    }
    // Candidates in preference order: the named platform/device, else GPUs first (prefer_gpu).
    cl_platform_id platform = nullptr;
    bool found = false;
    for (int pass = 0; pass < 2 && !found; ++pass) {
      for (size_t p = 0; p < ps.size() && !found; ++p) {
        if (choice.platform >= 0 && static_cast<int>(p) != choice.platform) continue;
        const std::vector<cl_device_id> ds = devicesOf(ps[p]);
        if (choice.device >= 0) {
          if (choice.device < static_cast<int>(ds.size())) {
            device_ = ds[static_cast<size_t>(choice.device)];
            platform = ps[p];
            found = true;
          }
          continue;
        }
        for (cl_device_id d : ds) {
          const bool gpu = isGpuDevice(d);
          if (pass == 0 && choice.prefer_gpu && !gpu) continue;
          device_ = d;
          platform = ps[p];
          found = true;
          break;
        }
      }
      if (choice.device >= 0) break;
    }
    if (!found) {
      err = choice.device >= 0 ? "OpenCL device index " + std::to_string(choice.device) + " does not exist"
                               : std::string("no OpenCL device");
      return false;
    }
    platform_name_ = platformString(platform, CL_PLATFORM_NAME);
    const cl_context_properties props[] = {CL_CONTEXT_PLATFORM, reinterpret_cast<cl_context_properties>(platform), 0};
    context_ = clCreateContext(props, 1, &device_, nullptr, nullptr, &rc);
    if (rc != CL_SUCCESS) {
      context_ = nullptr;
      err = std::string("clCreateContext failed (") + clErrorName(rc) + ")";
      return false;
    }
    // Profiling on: per-command times separate transfers from kernels (stats, benchmark).
    queue_ = clCreateCommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE, &rc);
    if (rc != CL_SUCCESS) {
      queue_ = nullptr;
      err = std::string("clCreateCommandQueue failed (") + clErrorName(rc) + ")";
      return false;
    }
    profiling_ = true;
  }
  device_name_ = deviceString(device_, CL_DEVICE_NAME);

  // Sizes: the work-group (256 or the device's limit) and the __local particle capacity (what
  // fits in the device's local memory after 4 KiB for the compiler's own use, at most 64 Ki).
  const size_t max_wg = deviceValue<size_t>(device_, CL_DEVICE_MAX_WORK_GROUP_SIZE);
  work_group_ = std::max<size_t>(1, std::min<size_t>(256, max_wg));
  const cl_ulong local = deviceValue<cl_ulong>(device_, CL_DEVICE_LOCAL_MEM_SIZE);
  local_particles_ = local > 4096 ? std::min<size_t>(65536, static_cast<size_t>((local - 4096) / 16)) : 1;
  gpu_ = isGpuDevice(device_);
  work_group_max_particles_ =
      std::min(local_particles_, gpu_ ? kGpuWorkGroupMaxParticles : kWorkGroupMaxParticles);

  // The program: the sources in their fixed order, the frame body twice (local, global).
  std::string source;
  for (size_t i = 0; i < kClSourceCount; ++i) {
    const std::string name = kClSources[i].name;
    if (name == "xpbd_frame.cl") {
      source += "#define DCL_XS __local\n#define DCL_FRAME_BODY drape_frame_local\n";
      source += kClSources[i].text;
      source += "\n#undef DCL_XS\n#undef DCL_FRAME_BODY\n#define DCL_XS __global\n#define DCL_FRAME_BODY drape_frame_global\n";
      source += kClSources[i].text;
      source += "\n#undef DCL_XS\n#undef DCL_FRAME_BODY\n";
    } else {
      source += kClSources[i].text;
      source += "\n";
    }
  }
  source += choice.extra_source;
  const char* text = source.c_str();
  const size_t length = source.size();
  program_ = clCreateProgramWithSource(context_, 1, &text, &length, &rc);
  if (rc != CL_SUCCESS) {
    program_ = nullptr;
    err = std::string("clCreateProgramWithSource failed (") + clErrorName(rc) + ")";
    return false;
  }
  // Correctly rounded division and square root: OpenCL allows 2.5-3 ulp otherwise, and the
  // collision response divides by small differences (friction, closest point) where that shows.
  const std::string options = "-cl-std=CL1.2 -cl-fp32-correctly-rounded-divide-sqrt -DDRAPE_CL_MAX_LOCAL_PARTICLES=" + std::to_string(local_particles_) +
                              " -DDRAPE_CL_WORK_GROUP=" + std::to_string(work_group_) + " " +
                              choice.extra_options;
  const auto t0 = std::chrono::steady_clock::now();
  rc = clBuildProgram(program_, 1, &device_, options.c_str(), nullptr, nullptr);
  build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (rc != CL_SUCCESS) {
    size_t size = 0;
    clGetProgramBuildInfo(program_, device_, CL_PROGRAM_BUILD_LOG, 0, nullptr, &size);
    std::string log(size, '\0');
    if (size > 0) clGetProgramBuildInfo(program_, device_, CL_PROGRAM_BUILD_LOG, size, &log[0], nullptr);
    log.resize(std::strlen(log.c_str()));
    constexpr size_t kMaxLog = 4000;  // the error API carries a bounded message
    if (log.size() > kMaxLog) log = log.substr(0, kMaxLog) + "\n[build log truncated]";
    err = std::string("OpenCL program build failed on ") + device_name_ + " (" + clErrorName(rc) +
          "), options \"" + options + "\":\n" + log;
    return false;
  }
  return true;
}

}  // namespace drape
