#include "backends/opencl/cl_stages.h"

#include <algorithm>
#include <chrono>

namespace drape {
namespace {

// Buffers and a kernel released at scope exit; every call checked, the first failure kept.
class Launch {
 public:
  Launch(ClRuntime& rt, const char* kernel, std::string& err) : rt_(rt), err_(err) {
    kernel_ = clCreateKernel(rt.program(), kernel, &rc_);
    if (rc_ != CL_SUCCESS) {
      kernel_ = nullptr;
      fail("clCreateKernel");
    }
  }
  ~Launch() {
    for (cl_mem m : mems_) clReleaseMemObject(m);
    if (kernel_) clReleaseKernel(kernel_);
  }
  bool ok() const { return rc_ == CL_SUCCESS; }
  // A buffer holding `bytes` of `data` (at least 16 bytes: empty arrays still get a valid buffer).
  cl_mem buffer(const void* data, size_t bytes) {
    if (!ok()) return nullptr;
    const size_t size = std::max<size_t>(bytes, 16);
    cl_mem m = clCreateBuffer(rt_.context(), CL_MEM_READ_WRITE, size, nullptr, &rc_);
    if (rc_ != CL_SUCCESS) {
      fail("clCreateBuffer");
      return nullptr;
    }
    mems_.push_back(m);
    if (bytes > 0 && data) {
      const auto t0 = Clock::now();
      rc_ = clEnqueueWriteBuffer(rt_.queue(), m, CL_TRUE, 0, bytes, data, 0, nullptr, nullptr);
      upload_ns += ns(t0);
      if (rc_ != CL_SUCCESS) fail("clEnqueueWriteBuffer");
    }
    return m;
  }
  template <class T>
  void arg(cl_uint i, const T& v) {
    if (ok() && (rc_ = clSetKernelArg(kernel_, i, sizeof(T), &v)) != CL_SUCCESS) fail("clSetKernelArg");
  }
  void run(size_t items) {
    if (!ok()) return;
    const size_t wg = 64, global = std::max<size_t>(wg, (items + wg - 1) / wg * wg);
    const auto t0 = Clock::now();
    rc_ = clEnqueueNDRangeKernel(rt_.queue(), kernel_, 1, nullptr, &global, &wg, 0, nullptr, nullptr);
    if (rc_ == CL_SUCCESS) rc_ = clFinish(rt_.queue());
    kernel_ns += ns(t0);
    if (rc_ != CL_SUCCESS) fail("kernel launch");
  }
  void read(cl_mem m, void* out, size_t bytes) {
    if (!ok() || bytes == 0) return;
    const auto t0 = Clock::now();
    rc_ = clEnqueueReadBuffer(rt_.queue(), m, CL_TRUE, 0, bytes, out, 0, nullptr, nullptr);
    readback_ns += ns(t0);
    if (rc_ != CL_SUCCESS) fail("clEnqueueReadBuffer");
  }
  void times(ClStageTimes* t) const {
    if (t) *t = ClStageTimes{upload_ns, kernel_ns, readback_ns};
  }
  double upload_ns = 0.0, kernel_ns = 0.0, readback_ns = 0.0;

 private:
  using Clock = std::chrono::steady_clock;
  static double ns(Clock::time_point t0) {
    return std::chrono::duration<double, std::nano>(Clock::now() - t0).count();
  }
  void fail(const char* what) {
    if (err_.empty()) err_ = std::string(what) + " failed (" + clErrorName(rc_) + ")";
    if (rc_ == CL_SUCCESS) rc_ = CL_INVALID_VALUE;
  }
  ClRuntime& rt_;
  std::string& err_;
  cl_kernel kernel_ = nullptr;
  cl_int rc_ = CL_SUCCESS;
  std::vector<cl_mem> mems_;
};

}  // namespace

bool clCollide(ClRuntime& rt, const std::vector<DrapeClShape>& shapes, const std::vector<DclF4>& bounds,
               const CollisionParams& params, const std::vector<uint8_t>& masks, std::vector<DclF4>& x,
               const std::vector<DclF4>& prev, CollisionStats& stats, std::string& err, ClStageTimes* times) {
  if (prev.size() != x.size() || bounds.size() < 2 || (!masks.empty() && masks.size() != x.size())) {
    err = "clCollide: mismatched array sizes";
    return false;
  }
  DrapeClGarment g{};
  g.shape_count = static_cast<uint32_t>(shapes.size());
  g.flags = (params.continuous ? DRAPE_CL_CONTINUOUS : 0u) |
            (params.response == ContactResponse::Exact ? DRAPE_CL_EXACT : 0u) | (masks.empty() ? 0u : DRAPE_CL_GROUPED);
  g.static_friction = params.static_friction > 0.0f ? std::min(params.static_friction, 1e6f) : 0.0f;
  g.kinetic_friction = params.kinetic_friction > 0.0f ? std::min(params.kinetic_friction, 1e6f) : 0.0f;
  g.max_escape = params.max_escape_m;
  Launch l(rt, "drape_collide", err);
  DrapeClStats st{};
  const cl_mem gb = l.buffer(&g, sizeof(g));
  const cl_mem xb = l.buffer(x.data(), x.size() * 16);
  const cl_mem pb = l.buffer(prev.data(), prev.size() * 16);
  const cl_mem mb = l.buffer(masks.data(), masks.size());
  const cl_mem sb = l.buffer(shapes.data(), shapes.size() * sizeof(DrapeClShape));
  const cl_mem bb = l.buffer(bounds.data(), bounds.size() * 16);
  const cl_mem stb = l.buffer(&st, sizeof(st));
  const cl_uint n = static_cast<cl_uint>(x.size());
  l.arg(0, gb);
  l.arg(1, xb);
  l.arg(2, pb);
  l.arg(3, mb);
  l.arg(4, sb);
  l.arg(5, bb);
  l.arg(6, n);
  l.arg(7, stb);
  l.run(x.size());
  l.read(xb, x.data(), x.size() * 16);
  l.read(stb, &st, sizeof(st));
  l.times(times);
  stats = CollisionStats{st.tests, st.contacts, st.swept_catches, st.escapes};
  return l.ok();
}

bool clProjectGroup(ClRuntime& rt, const std::vector<DrapeClConstraint>& constraints, uint32_t begin, uint32_t end,
                    uint32_t mode, float scale, float alpha, std::vector<DclF4>& x, std::string& err,
                    ClStageTimes* times) {
  if (begin > end || end > constraints.size()) {
    err = "clProjectGroup: bad range";
    return false;
  }
  if (mode > DCL_MODE_LIMIT) {
    err = "clProjectGroup: bad mode";
    return false;
  }
  Launch l(rt, "drape_project_group", err);
  const cl_mem xb = l.buffer(x.data(), x.size() * 16);
  const cl_mem cb = l.buffer(constraints.data(), constraints.size() * sizeof(DrapeClConstraint));
  const cl_uint m = mode;
  l.arg(0, xb);
  l.arg(1, cb);
  l.arg(2, static_cast<cl_uint>(begin));
  l.arg(3, static_cast<cl_uint>(end));
  l.arg(4, m);
  l.arg(5, scale);
  l.arg(6, alpha);
  l.run(end - begin);
  l.read(xb, x.data(), x.size() * 16);
  l.times(times);
  return l.ok();
}

bool clVertexNormals(ClRuntime& rt, const std::vector<DclF4>& x, const std::vector<uint32_t>& indices,
                     std::vector<DclF4>& normals, std::string& err, ClStageTimes* times) {
  // Vertex -> triangles (ascending), so each work-item sums its own normal: no atomics.
  const size_t n = x.size(), tris = indices.size() / 3;
  std::vector<uint32_t> offsets(n + 1, 0), faces(3 * tris);
  for (size_t t = 0; t < tris; ++t)
    for (int c = 0; c < 3; ++c) {
      if (indices[3 * t + c] >= n) {
        err = "clVertexNormals: index out of range";
        return false;
      }
      ++offsets[indices[3 * t + c] + 1];
    }
  for (size_t i = 0; i < n; ++i) offsets[i + 1] += offsets[i];
  std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (size_t t = 0; t < tris; ++t)
    for (int c = 0; c < 3; ++c) faces[fill[indices[3 * t + c]]++] = static_cast<uint32_t>(t);
  normals.assign(n, DclF4{0, 0, 0, 0});
  Launch l(rt, "drape_vertex_normals", err);
  const cl_mem xb = l.buffer(x.data(), n * 16);
  const cl_mem ib = l.buffer(indices.data(), indices.size() * 4);
  const cl_mem ob = l.buffer(offsets.data(), offsets.size() * 4);
  const cl_mem fb = l.buffer(faces.data(), faces.size() * 4);
  const cl_mem nb = l.buffer(nullptr, n * 16);
  l.arg(0, xb);
  l.arg(1, ib);
  l.arg(2, ob);
  l.arg(3, fb);
  l.arg(4, static_cast<cl_uint>(n));
  l.arg(5, nb);
  l.arg(6, cl_uint{0});
  l.run(n);
  l.read(nb, normals.data(), n * 16);
  l.times(times);
  return l.ok();
}

}  // namespace drape
