// ClFrameBatch: many garments' frames in one drape_xpbd_frame launch. cl_frame_batch.h.
#include "backends/opencl/cl_frame_batch.h"

#include <algorithm>

namespace drape {

ClFrameBatch::ClFrameBatch(ClRuntime& runtime) : runtime_(runtime) {}

ClFrameBatch::~ClFrameBatch() {
  if (frame_) clReleaseKernel(frame_);
  if (transform_) clReleaseKernel(transform_);
  if (normals_) clReleaseKernel(normals_);
  for (Buffer* b : {&garments_, &x_, &prev_, &v_, &span_start_, &pin_start_, &pin_index_, &pin_target_, &constraints_,
                    &groups_, &masks_, &shapes_, &bounds_, &stats_, &transforms_, &work_, &triangles_, &face_offsets_,
                    &vertex_faces_})
    release(b->mem);
}

bool ClFrameBatch::grow(cl_mem& buffer, size_t& capacity, size_t bytes, cl_mem_flags flags) {
  bytes = std::max<size_t>(bytes, 16);
  if (buffer && bytes <= capacity) return true;
  release(buffer);
  // Half as much again: a growing crowd of garments reallocates a few times, not every frame.
  capacity = bytes + bytes / 2;
  cl_int rc = CL_SUCCESS;
  buffer = clCreateBuffer(runtime_.context(), flags, capacity, nullptr, &rc);
  if (rc != CL_SUCCESS) {
    buffer = nullptr;
    capacity = 0;
    return false;
  }
  return true;
}

bool ClFrameBatch::run(const std::vector<ClXpbdSolver*>& solvers, std::string& err) {
  std::lock_guard<std::mutex> lock(mutex_);
  members_.assign(solvers.begin(), solvers.end());
  std::stable_partition(members_.begin(), members_.end(), [](const ClXpbdSolver* s) { return !s->usesPhases(); });
  const bool ok = runLocked(members_, err);
  for (ClXpbdSolver* s : solvers) {
    s->prepared_ = false;
    if (!ok) {
      s->device_error_ = err;
      clFinish(runtime_.queue());
      s->uploadState();  // the device copy may be half-stepped: restore the last good one
    }
  }
  return ok;
}

bool ClFrameBatch::runLocked(const std::vector<ClXpbdSolver*>& solvers, std::string& err) {
  for (const ClXpbdSolver* s : solvers) {
    if (!s->prepared_ || s->particleCount() == 0 || &s->runtime() != &runtime_) {
      err = "ClFrameBatch: a member is not a prepared frame on this runtime";
      return false;
    }
  }
  cl_int rc = CL_SUCCESS;
  for (auto [kernel, name] : {std::pair<cl_kernel*, const char*>{&frame_, "drape_xpbd_frame"},
                              std::pair<cl_kernel*, const char*>{&transform_, "drape_transform_batch"},
                              std::pair<cl_kernel*, const char*>{&normals_, "drape_vertex_normals"}}) {
    if (*kernel) continue;
    *kernel = clCreateKernel(runtime_.program(), name, &rc);
    if (rc != CL_SUCCESS) {
      *kernel = nullptr;
      err = std::string("clCreateKernel failed (") + clErrorName(rc) + ")";
      return false;
    }
  }
  if (!phases_.create(runtime_.program(), err)) return false;
  // The table: each garment's record with its slices of the concatenated buffers.
  const size_t count = solvers.size();
  size_t work_groups = 0;  // the leading one-work-group members
  while (work_groups < count && !solvers[work_groups]->usesPhases()) ++work_groups;
  plan_.clear(count);
  table_.resize(count);
  pin_targets_.clear();
  shapes_host_.clear();
  bounds_host_.clear();
  std::vector<uint64_t>& layout = next_layout_;  // scratch, kept between frames
  layout.clear();
  size_t particles = 0, pins = 0, constraints = 0, groups = 0;
  for (size_t i = 0; i < count; ++i) {
    const ClXpbdSolver& s = *solvers[i];
    DrapeClGarment g = s.frame_g_;
    g.particle_offset = static_cast<uint32_t>(particles);
    g.distance_group_offset = static_cast<uint32_t>(groups);
    g.tether_group_offset = static_cast<uint32_t>(groups + s.distance_groups_ + 1);
    g.rim_group_offset = static_cast<uint32_t>(groups + s.rim_group_offset_);
    g.pin_offset = static_cast<uint32_t>(pins);
    g.shape_offset = static_cast<uint32_t>(shapes_host_.size());
    g.span_offset = static_cast<uint32_t>(bounds_host_.size() / 2);
    table_[i] = g;
    particles += s.particleCount();
    pins += s.pin_index_.size();
    constraints += s.constraints_.size();
    groups += s.group_offsets_.size();
    pin_targets_.insert(pin_targets_.end(), s.pin_target4_.begin(), s.pin_target4_.end());
    shapes_host_.insert(shapes_host_.end(), s.shapes_.begin(), s.shapes_.end());
    bounds_host_.insert(bounds_host_.end(), s.bounds_.begin(), s.bounds_.end());
    layout.push_back(s.batch_id_);
    if (i >= work_groups)
      plan_.setGarment(i, static_cast<uint32_t>(s.particleCount()), static_cast<uint32_t>(s.pin_index_.size()),
                       s.group_offsets_, s.distance_groups_, s.tether_groups_);
  }
  plan_.finish();
  const cl_mem_flags rw = CL_MEM_READ_WRITE, ro = CL_MEM_READ_ONLY;
  bool ok = grow(garments_.mem, garments_.capacity, count * sizeof(DrapeClGarment), ro) &&
            grow(x_.mem, x_.capacity, 2 * particles * 16, rw) &&  // positions, then normals
            grow(prev_.mem, prev_.capacity, particles * 16, rw) &&
            grow(v_.mem, v_.capacity, particles * 16, rw) &&
            grow(span_start_.mem, span_start_.capacity, particles * 16, rw) &&
            grow(pin_start_.mem, pin_start_.capacity, pins * 16, rw) &&
            grow(pin_target_.mem, pin_target_.capacity, pins * 16, ro) &&
            grow(shapes_.mem, shapes_.capacity, shapes_host_.size() * sizeof(DrapeClShape), ro) &&
            grow(bounds_.mem, bounds_.capacity, bounds_host_.size() * 16, ro) &&
            grow(stats_.mem, stats_.capacity, count * sizeof(DrapeClStats), rw) &&
            grow(work_.mem, work_.capacity, plan_.work().size() * 4, ro);
  // Static data: again only when the members changed (the constraints are fixed per solver: a
  // new h changes only the garment records' alpha). A reallocated static buffer forgets its
  // contents, so it forces the upload too.
  const size_t pin_index_cap = pin_index_.capacity, constraint_cap = constraints_.capacity,
               group_cap = groups_.capacity, mask_cap = masks_.capacity, triangle_cap = triangles_.capacity,
               face_offset_cap = face_offsets_.capacity, vertex_face_cap = vertex_faces_.capacity;
  size_t triangle_indices = 0, face_entries = 0;
  for (const ClXpbdSolver* s : solvers) {
    triangle_indices += s->normal_tables_.indices.size();
    face_entries += s->normal_tables_.vertex_faces.size();
  }
  ok = ok && grow(pin_index_.mem, pin_index_.capacity, pins * 4, ro) &&
       grow(constraints_.mem, constraints_.capacity, constraints * sizeof(DrapeClConstraint), ro) &&
       grow(groups_.mem, groups_.capacity, groups * 4, ro) && grow(masks_.mem, masks_.capacity, particles, ro) &&
       grow(triangles_.mem, triangles_.capacity, triangle_indices * 4, ro) &&
       grow(face_offsets_.mem, face_offsets_.capacity, (particles + 1) * 4, ro) &&
       grow(vertex_faces_.mem, vertex_faces_.capacity, face_entries * 4, ro);
  if (!ok) {
    layout_.clear();
    err = "OpenCL batch buffer allocation failed";
    return false;
  }
  const bool reallocated = pin_index_cap != pin_index_.capacity || constraint_cap != constraints_.capacity ||
                           group_cap != groups_.capacity || mask_cap != masks_.capacity ||
                           triangle_cap != triangles_.capacity || face_offset_cap != face_offsets_.capacity ||
                           vertex_face_cap != vertex_faces_.capacity;
  cl_command_queue q = runtime_.queue();
  auto write = [&](cl_mem m, size_t offset, const void* data, size_t bytes) {
    if (rc == CL_SUCCESS && bytes > 0) rc = clEnqueueWriteBuffer(q, m, CL_FALSE, offset, bytes, data, 0, nullptr, nullptr);
  };
  auto copy = [&](cl_mem from, size_t from_offset, cl_mem to, size_t to_offset, size_t bytes) {
    if (rc == CL_SUCCESS && bytes > 0) rc = clEnqueueCopyBuffer(q, from, to, from_offset, to_offset, bytes, 0, nullptr, nullptr);
  };
  if (reallocated || layout != layout_) {
    layout_.clear();  // until the uploads below are queued
    constraints_host_.clear();
    constraint_versions_.clear();
    groups_host_.clear();
    pin_index_host_.clear();
    masks_host_.clear();
    normal_tables_.clear();
    for (const ClXpbdSolver* s : solvers) {
      normal_tables_.append(s->topology_.triangles, s->particleCount());  // checked by the solver
      // Group table entries index the concatenated constraints.
      const uint32_t base = static_cast<uint32_t>(constraints_host_.size());
      for (uint32_t o : s->group_offsets_) groups_host_.push_back(base + o);
      constraints_host_.insert(constraints_host_.end(), s->constraints_.begin(), s->constraints_.end());
      constraint_versions_.push_back(s->constraints_version_);
      pin_index_host_.insert(pin_index_host_.end(), s->pin_index_.begin(), s->pin_index_.end());
      // As the solver's own buffer: every group for particles without a mask.
      const size_t n = std::min(s->masks_.size(), s->particleCount());
      masks_host_.insert(masks_host_.end(), s->masks_.begin(), s->masks_.begin() + static_cast<long>(n));
      masks_host_.insert(masks_host_.end(), s->particleCount() - n, uint8_t{0xFF});
    }
    write(constraints_.mem, 0, constraints_host_.data(), constraints_host_.size() * sizeof(DrapeClConstraint));
    write(groups_.mem, 0, groups_host_.data(), groups_host_.size() * 4);
    write(pin_index_.mem, 0, pin_index_host_.data(), pin_index_host_.size() * 4);
    write(masks_.mem, 0, masks_host_.data(), masks_host_.size());
    write(triangles_.mem, 0, normal_tables_.indices.data(), normal_tables_.indices.size() * 4);
    write(face_offsets_.mem, 0, normal_tables_.face_offsets.data(), normal_tables_.face_offsets.size() * 4);
    write(vertex_faces_.mem, 0, normal_tables_.vertex_faces.data(), normal_tables_.vertex_faces.size() * 4);
    if (rc == CL_SUCCESS) layout_ = layout;
  }
  // A member whose rim gate changed since its constraints went up: its records again (its slice).
  size_t base = 0;
  for (size_t i = 0; i < count && i < constraint_versions_.size(); ++i) {
    const ClXpbdSolver& s = *solvers[i];
    if (s.constraints_version_ != constraint_versions_[i]) {
      std::copy(s.constraints_.begin(), s.constraints_.end(), constraints_host_.begin() + static_cast<long>(base));
      write(constraints_.mem, base * sizeof(DrapeClConstraint), constraints_host_.data() + base,
            s.constraints_.size() * sizeof(DrapeClConstraint));
      constraint_versions_[i] = s.constraints_version_;
    }
    base += s.constraints_.size();
  }
  write(garments_.mem, 0, table_.data(), count * sizeof(DrapeClGarment));
  write(pin_target_.mem, 0, pin_targets_.data(), pin_targets_.size() * 16);
  write(shapes_.mem, 0, shapes_host_.data(), shapes_host_.size() * sizeof(DrapeClShape));
  write(bounds_.mem, 0, bounds_host_.data(), bounds_host_.size() * 16);
  if (plan_.any()) write(work_.mem, 0, plan_.work().data(), plan_.work().size() * 4);
  // The garments' state in (device to device): positions and velocities. prev, span_start and
  // pin_start are scratch the kernel writes before it reads them.
  for (size_t i = 0; i < count; ++i) {
    const size_t bytes = solvers[i]->particleCount() * 16;
    copy(solvers[i]->x_buf_, 0, x_.mem, size_t{table_[i].particle_offset} * 16, bytes);
    copy(solvers[i]->v_buf_, 0, v_.mem, size_t{table_[i].particle_offset} * 16, bytes);
  }
  // The deferred rigid carries (inertia scaling) of every member: one launch for all.
  transforms_host_.clear();
  for (size_t i = 0; i < count; ++i) {
    ClXpbdSolver& s = *solvers[i];
    if (!s.transform_pending_) continue;
    DrapeClTransform m = s.pending_transform_;
    m.offset = table_[i].particle_offset;
    transforms_host_.push_back(m);
    s.transform_pending_ = false;
  }
  if (!transforms_host_.empty()) {
    const size_t bytes = transforms_host_.size() * sizeof(DrapeClTransform);
    if (!grow(transforms_.mem, transforms_.capacity, bytes, ro)) {
      err = "OpenCL batch buffer allocation failed";
      return false;
    }
    write(transforms_.mem, 0, transforms_host_.data(), bytes);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(transform_, 0, sizeof(cl_mem), &x_.mem);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(transform_, 1, sizeof(cl_mem), &v_.mem);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(transform_, 2, sizeof(cl_mem), &transforms_.mem);
    if (rc == CL_SUCCESS) {
      const size_t wg = 64, global = wg * transforms_host_.size();
      rc = clEnqueueNDRangeKernel(q, transform_, 1, nullptr, &global, &wg, 0, nullptr, nullptr);
      runtime_.countLaunches();
    }
  }
  const cl_mem args[14] = {garments_.mem, x_.mem,           prev_.mem,         v_.mem,      span_start_.mem,
                           pin_start_.mem, pin_index_.mem,  pin_target_.mem,   constraints_.mem, groups_.mem,
                           masks_.mem,    shapes_.mem,      bounds_.mem,       stats_.mem};
  for (cl_uint a = 0; a < 14 && rc == CL_SUCCESS && work_groups > 0; ++a)
    rc = clSetKernelArg(frame_, a, sizeof(cl_mem), &args[a]);
  if (rc == CL_SUCCESS && work_groups > 0) {
    const size_t wg = runtime_.workGroup(), global = wg * work_groups;
    rc = clEnqueueNDRangeKernel(q, frame_, 1, nullptr, &global, &wg, 0, nullptr, nullptr);
    runtime_.countLaunches();
  }
  // The per-phase members: each phase once for all of them (their own substep loop).
  if (rc == CL_SUCCESS && plan_.any()) rc = enqueuePhases();
  // The state back to each garment's own buffers (its transform, velocities() and a later
  // solo frame use them), then one readback of every position and counter.
  for (size_t i = 0; i < count; ++i) {
    const size_t bytes = solvers[i]->particleCount() * 16;
    copy(x_.mem, size_t{table_[i].particle_offset} * 16, solvers[i]->x_buf_, 0, bytes);
    copy(v_.mem, size_t{table_[i].particle_offset} * 16, solvers[i]->v_buf_, 0, bytes);
  }
  // Normals of every member when one asked for them (the same kernel and arithmetic as a
  // garment's own frame), written after the positions.
  bool normals = false;
  for (const ClXpbdSolver* s : solvers) normals = normals || s->normals_frame_;
  if (normals && rc == CL_SUCCESS) {
    const cl_uint n = static_cast<cl_uint>(particles);
    const cl_mem nargs[4] = {x_.mem, triangles_.mem, face_offsets_.mem, vertex_faces_.mem};
    for (cl_uint a = 0; a < 4 && rc == CL_SUCCESS; ++a) rc = clSetKernelArg(normals_, a, sizeof(cl_mem), &nargs[a]);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(normals_, 4, sizeof(n), &n);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(normals_, 5, sizeof(cl_mem), &x_.mem);
    if (rc == CL_SUCCESS) rc = clSetKernelArg(normals_, 6, sizeof(n), &n);
    const size_t global = (particles + 63) / 64 * 64;
    if (rc == CL_SUCCESS) {
      rc = clEnqueueNDRangeKernel(q, normals_, 1, nullptr, &global, nullptr, 0, nullptr, nullptr);
      runtime_.countLaunches();
    }
  }
  const size_t rows = normals ? 2 * particles : particles;
  stats_host_.resize(count);
  x_host_.resize(rows);
  if (rc == CL_SUCCESS)
    rc = clEnqueueReadBuffer(q, stats_.mem, CL_FALSE, 0, count * sizeof(DrapeClStats), stats_host_.data(), 0, nullptr, nullptr);
  if (rc == CL_SUCCESS)
    rc = clEnqueueReadBuffer(q, x_.mem, CL_TRUE, 0, rows * 16, x_host_.data(), 0, nullptr, nullptr);
  if (rc == CL_SUCCESS) rc = clFinish(q);
  if (rc != CL_SUCCESS) {
    layout_.clear();  // the static uploads may not have landed
    err = std::string("OpenCL batched frame failed (") + clErrorName(rc) + ")";
    return false;
  }
  for (size_t i = 0; i < count; ++i) {
    ClXpbdSolver& s = *solvers[i];
    std::copy(x_host_.begin() + static_cast<long>(size_t{table_[i].particle_offset}),
              x_host_.begin() + static_cast<long>(size_t{table_[i].particle_offset} + s.particleCount()), s.x_.begin());
    s.v_stale_ = true;
    s.normals_valid_ = normals;
    if (normals) {
      const auto from = x_host_.begin() + static_cast<long>(particles + size_t{table_[i].particle_offset});
      s.normals_.assign(from, from + static_cast<long>(s.particleCount()));
    }
    s.collision_stats_ = toCollisionStats(stats_host_[i]);
  }
  return true;
}

cl_int ClFrameBatch::enqueuePhases() {
  ClPhaseBuffers b;
  b.table = garments_.mem, b.work = work_.mem, b.x = x_.mem, b.prev = prev_.mem, b.v = v_.mem;
  b.span_start = span_start_.mem, b.pin_start = pin_start_.mem, b.pin_index = pin_index_.mem;
  b.pin_target = pin_target_.mem, b.constraints = constraints_.mem, b.groups = groups_.mem, b.masks = masks_.mem;
  b.shapes = shapes_.mem, b.bounds = bounds_.mem, b.stats = stats_.mem;
  return phases_.enqueue(runtime_, b, plan_, table_.data(), nullptr, nullptr);
}

}  // namespace drape
