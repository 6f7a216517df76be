// ClXpbdSolver::step: one frame on the device, as one work-group launch (drape_xpbd_frame) or
// one launch per phase (large garments); the transfers around it. cl_xpbd_solver.h.
#include "backends/opencl/cl_shapes.h"
#include "backends/opencl/cl_xpbd_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace drape {
namespace {

using Clock = std::chrono::steady_clock;

double eventNs(cl_event e) {
  cl_ulong a = 0, b = 0;
  if (clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_START, sizeof(a), &a, nullptr) != CL_SUCCESS ||
      clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_END, sizeof(b), &b, nullptr) != CL_SUCCESS)
    return 0.0;
  return static_cast<double>(b - a);
}

double sumAndRelease(std::vector<cl_event>& events, bool profiling) {
  double ns = 0.0;
  for (cl_event e : events) {
    if (profiling) ns += eventNs(e);
    clReleaseEvent(e);
  }
  events.clear();
  return ns;
}

}  // namespace

bool ClXpbdSolver::enqueuePhases(std::vector<cl_event>& runs) {
  ClPhaseBuffers b;
  b.table = garment_, b.work = work_buf_, b.x = x_buf_, b.prev = prev_buf_, b.v = v_buf_;
  b.span_start = span_start_buf_, b.pin_start = pin_start_buf_, b.pin_index = pin_index_buf_;
  b.pin_target = pin_target_buf_, b.constraints = constraint_buf_, b.groups = group_buf_, b.masks = mask_buf_;
  b.shapes = shape_buf_, b.bounds = bounds_buf_, b.stats = stats_buf_;
  // The first and the last launch keep their events: the kernel time spans them.
  cl_event first = nullptr, last = nullptr;
  const cl_int rc = phases_.enqueue(*runtime_, b, phase_plan_, &frame_g_, &first, &last);
  for (cl_event e : {first, last})
    if (e) runs.push_back(e);
  if (rc != CL_SUCCESS) {
    device_error_ = std::string("OpenCL phase launch failed (") + clErrorName(rc) + ")";
    return false;
  }
  return true;
}

bool ClXpbdSolver::enqueueNormals() {
  const cl_uint n = static_cast<cl_uint>(particleCount());
  cl_int rc = CL_SUCCESS;
  auto arg = [&](cl_uint i, auto v) {
    if (rc == CL_SUCCESS) rc = clSetKernelArg(normals_kernel_, i, sizeof(v), &v);
  };
  arg(0, x_buf_), arg(1, tri_buf_), arg(2, face_offset_buf_), arg(3, vertex_face_buf_), arg(4, n), arg(5, x_buf_),
      arg(6, n);
  const size_t global = (size_t{n} + 63) / 64 * 64;
  if (rc == CL_SUCCESS) {
    rc = clEnqueueNDRangeKernel(runtime_->queue(), normals_kernel_, 1, nullptr, &global, nullptr, 0, nullptr, nullptr);
    runtime_->countLaunches();
  }
  if (rc != CL_SUCCESS) {
    device_error_ = std::string("OpenCL normals launch failed (") + clErrorName(rc) + ")";
    return false;
  }
  return true;
}

bool ClXpbdSolver::step(float dt, int substeps) { return prepareFrame(dt, substeps) && runPreparedFrame(); }

bool ClXpbdSolver::prepareFrame(float dt, int substeps) {
  prepared_ = false;
  if (!(dt > 0.0f) || !(dt <= 1.0f) || substeps < 1 || substeps > 1000) return false;
  timings_ = ClStepTimings{};
  collision_stats_ = CollisionStats{};
  const size_t n = particleCount();
  prepared_ = true;
  // Normals with this frame when the host read them since the last one (requestNormals).
  normals_frame_ = normals_requested_;
  normals_requested_ = false;
  if (n == 0) return true;
  const auto host0 = Clock::now();
  const float h = dt / static_cast<float>(substeps);
  const float inv_h2 = 1.0f / (h * h);
  const int count = static_cast<int>(motion_start_.size());
  const int stride = collisionStrideFor(params_.collision_stride, n);
  if (count > 0) {
    packFrameShapes(motion_start_.data(), motion_end_.data(), count, motion_margin_, groups_, substeps, stride,
                    shapes_, bounds_);
  } else {
    shapes_.clear();
    bounds_.clear();
  }
  for (size_t k = 0; k < pin_target_.size(); ++k)
    pin_target4_[k] = DclF4{pin_target_[k].x(), pin_target_[k].y(), pin_target_[k].z(), 0.0f};

  const XpbdParams& p = params_;
  DrapeClGarment& g = frame_g_;
  g = DrapeClGarment{};
  g.hg = DclF4{h * p.gravity.x(), h * p.gravity.y(), h * p.gravity.z(), 0.0f};
  g.wind = DclF4{p.wind.x(), p.wind.y(), p.wind.z(), 0.0f};
  g.particle_offset = 0;
  g.particle_count = static_cast<uint32_t>(n);
  g.distance_group_offset = 0;
  g.distance_groups = distance_groups_;
  g.tether_group_offset = distance_groups_ + 1;
  g.tether_groups = tether_groups_;
  g.rim_group_offset = rim_group_offset_;
  g.rim_groups = params_.collision.rims ? rim_groups_ : 0u;
  g.pin_offset = 0;
  g.pin_count = static_cast<uint32_t>(pin_index_.size());
  g.shape_offset = 0;
  g.shape_count = static_cast<uint32_t>(count);
  g.span_offset = 0;
  const CollisionParams& cp = p.collision;
  g.flags = (cp.continuous ? DRAPE_CL_CONTINUOUS : 0u) | (cp.response == ContactResponse::Exact ? DRAPE_CL_EXACT : 0u) |
            (!masks_.empty() && groups_.size() == static_cast<size_t>(count) && count > 0 &&
                     count <= EllipsoidCollider::kMaxGridEllipsoids
                 ? DRAPE_CL_GROUPED
                 : 0u) |
            (n <= runtime_->localParticles() ? DRAPE_CL_LOCAL : 0u);
  g.substeps = substeps;
  g.stride = stride;
  g.iterations = p.iterations;
  g.h = h;
  g.inv_n = 1.0f / static_cast<float>(substeps);
  g.h_drag = h * p.drag;
  g.max_speed = p.max_speed;
  g.max_speed2 = p.max_speed > 0.0f ? p.max_speed * p.max_speed : 0.0f;
  g.velocity_scale = std::exp(-p.damping * h) / h;
  g.tether_scale = p.tether_scale;
  // The strain limit's passes over the stretch groups in the frame's last substep (0: off, as
  // XpbdSolver::substep skips them), each edge held to rest * (1 + strain_limit).
  g.strain_passes = p.strain_limit > 0.0f ? p.strain_limit_passes : 0;
  g.strain_scale = 1.0f + p.strain_limit;
  // The collider clamps friction to [0, 1e6] (NaN -> 0).
  g.static_friction = cp.static_friction > 0.0f ? std::min(cp.static_friction, 1e6f) : 0.0f;
  g.kinetic_friction = cp.kinetic_friction > 0.0f ? std::min(cp.kinetic_friction, 1e6f) : 0.0f;
  g.max_escape = cp.max_escape_m;
  // alpha~ = compliance / h^2 per kind, as XpbdSolver forms it (compliance * inv_h2): the kernels
  // add it to each constraint's static w_sum, so a new h costs nothing more than this record.
  const float by_kind[3] = {p.stretch_compliance, p.shear_compliance, p.bend_compliance};
  for (int slot = 0; slot < 3; ++slot) g.alpha[slot] = by_kind[kDistanceKindOrder[slot]] * inv_h2;
  g.alpha[3] = p.tether_compliance * inv_h2;
  g.kind_end[0] = kind_end_[0];
  g.kind_end[1] = kind_end_[1];
  timings_.host_ns = std::chrono::duration<double, std::nano>(Clock::now() - host0).count();
  return true;
}

bool ClXpbdSolver::runPreparedFrame() {
  if (!prepared_) return false;
  prepared_ = false;
  const size_t n = particleCount();
  if (n == 0) return true;
  flushTransform();
  const DrapeClGarment& g = frame_g_;

  // Grow the shape buffers (rare: more substeps or ellipsoids than before).
  cl_int rc = CL_SUCCESS;
  if (shapes_.size() > shape_capacity_) {
    release(shape_buf_);
    shape_capacity_ = shapes_.size() * 2;
    shape_buf_ = clCreateBuffer(runtime_->context(), CL_MEM_READ_ONLY, shape_capacity_ * sizeof(DrapeClShape), nullptr, &rc);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(frame_, 11, sizeof(cl_mem), &shape_buf_);
  }
  if (rc == CL_SUCCESS && bounds_.size() > bounds_capacity_) {
    release(bounds_buf_);
    bounds_capacity_ = bounds_.size() * 2;
    bounds_buf_ = clCreateBuffer(runtime_->context(), CL_MEM_READ_ONLY, bounds_capacity_ * 16, nullptr, &rc);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(frame_, 12, sizeof(cl_mem), &bounds_buf_);
  }
  if (rc != CL_SUCCESS) {
    device_error_ = std::string("OpenCL shape buffer failed (") + clErrorName(rc) + ")";
    return false;
  }
  // Events and readback in scratch kept between frames: no allocation per frame.
  std::vector<cl_event>& writes = writes_;
  std::vector<cl_event>& runs = runs_;
  std::vector<cl_event>& reads = reads_;
  const auto wall0 = Clock::now();
  bool ok = upload(garment_, &g, sizeof(g), &writes) &&
            upload(pin_target_buf_, pin_target4_.data(), pin_target4_.size() * 16, &writes) &&
            upload(shape_buf_, shapes_.data(), shapes_.size() * sizeof(DrapeClShape), &writes) &&
            upload(bounds_buf_, bounds_.data(), bounds_.size() * 16, &writes);
  if (ok && constraints_dirty_ && !constraints_.empty()) {
    ok = upload(constraint_buf_, constraints_.data(), constraints_.size() * sizeof(DrapeClConstraint), &writes);
    constraints_dirty_ = !ok;
  }
  if (ok && usesPhases()) {
    ok = enqueuePhases(runs);
  } else if (ok) {
    const size_t wg = runtime_->workGroup();
    cl_event e = nullptr;
    rc = clEnqueueNDRangeKernel(runtime_->queue(), frame_, 1, nullptr, &wg, &wg, 0, nullptr, &e);
    runtime_->countLaunches();
    if (rc == CL_SUCCESS) {
      runs.push_back(e);
    } else {
      device_error_ = std::string("clEnqueueNDRangeKernel failed (") + clErrorName(rc) + ")";
      ok = false;
    }
  }
  normals_valid_ = false;
  if (ok && normals_frame_) ok = enqueueNormals();
  // Positions, and after them the normals when the frame computed them: one readback.
  const size_t rows = normals_frame_ ? 2 * n : n;
  DrapeClStats stats{};
  std::vector<Eigen::Vector4f>& x_back = readback_;
  if (ok) {
    x_back.resize(rows);
    cl_event e1 = nullptr, e2 = nullptr;
    rc = clEnqueueReadBuffer(runtime_->queue(), stats_buf_, CL_FALSE, 0, sizeof(stats), &stats, 0, nullptr, &e1);
    if (rc == CL_SUCCESS) {
      reads.push_back(e1);
      rc = clEnqueueReadBuffer(runtime_->queue(), x_buf_, CL_TRUE, 0, rows * 16, x_back.data(), 0, nullptr, &e2);
      if (rc == CL_SUCCESS) reads.push_back(e2);
    }
    if (rc == CL_SUCCESS) rc = clFinish(runtime_->queue());
    if (rc != CL_SUCCESS) {
      device_error_ = std::string("OpenCL frame failed (") + clErrorName(rc) + ")";
      ok = false;
    }
  }
  const double wall = std::chrono::duration<double, std::nano>(Clock::now() - wall0).count();
  const bool prof = runtime_->profiling();
  timings_.upload_ns = sumAndRelease(writes, prof);
  if (runs.size() > 1) {
    // Phases: from the first launch's start to the last one's end (launch gaps included).
    cl_ulong first = 0, last = 0;
    if (prof && clGetEventProfilingInfo(runs.front(), CL_PROFILING_COMMAND_START, sizeof(first), &first, nullptr) == CL_SUCCESS &&
        clGetEventProfilingInfo(runs.back(), CL_PROFILING_COMMAND_END, sizeof(last), &last, nullptr) == CL_SUCCESS)
      timings_.kernel_ns = static_cast<double>(last - first);
    sumAndRelease(runs, false);
  } else {
    timings_.kernel_ns = sumAndRelease(runs, prof);
  }
  timings_.readback_ns = sumAndRelease(reads, prof);
  if (!prof) timings_.kernel_ns = wall;
  if (!ok) {
    clFinish(runtime_->queue());
    uploadState();  // the device state may be half-stepped: restore the last good one
    return false;
  }
  if (normals_frame_) {
    normals_.assign(x_back.begin() + static_cast<long>(n), x_back.end());
    normals_valid_ = true;
  }
  std::copy(x_back.begin(), x_back.begin() + static_cast<long>(n), x_.begin());
  v_stale_ = true;
  collision_stats_ = toCollisionStats(stats);
  return true;
}

}  // namespace drape
