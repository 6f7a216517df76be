#include "backends/opencl/cl_xpbd_solver.h"

#include "backends/opencl/cl_shapes.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>

namespace drape {
namespace {

// Appends the colour groups of `c` to the device lists; w_sum = w_a + w_b (one-sided tethers:
// w_a), the part of 1 / (w_a + w_b + alpha~) that does not change with h (DrapeClConstraint).
void appendGroups(const DistanceConstraints& c, bool one_sided, const std::vector<float>& w,
                  std::vector<DrapeClConstraint>& out, std::vector<uint32_t>& offsets) {
  for (size_t g = 0; g < c.colours(); ++g) {
    for (uint32_t k = c.colour_offsets[g]; k < c.colour_offsets[g + 1]; ++k)
      out.push_back(DrapeClConstraint{c.a[k], c.b[k], c.rest[k], w[c.a[k]] + (one_sided ? 0.0f : w[c.b[k]])});
    offsets.push_back(static_cast<uint32_t>(out.size()));
  }
}

}  // namespace

std::unique_ptr<ClXpbdSolver> ClXpbdSolver::create(std::shared_ptr<ClRuntime> runtime, GarmentTopology topology,
                                                   std::vector<uint8_t> masks, std::vector<uint8_t> groups,
                                                   std::string& err) {
  if (!runtime) {
    err = "no OpenCL runtime";
    return nullptr;
  }
  if (!masks.empty() && masks.size() != topology.particleCount()) {
    err = "one collision mask per particle expected";
    return nullptr;
  }
  std::unique_ptr<ClXpbdSolver> s(new ClXpbdSolver());
  static std::atomic<uint64_t> next_id{1};
  s->batch_id_ = next_id++;
  s->runtime_ = std::move(runtime);
  s->topology_ = std::move(topology);
  s->masks_ = std::move(masks);
  s->groups_ = std::move(groups);
  const size_t n = s->topology_.particleCount();
  s->x_.resize(n);
  s->v_.assign(n, Eigen::Vector4f::Zero());
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = s->topology_.rest_positions[i];
    s->x_[i] = Eigen::Vector4f(p.x(), p.y(), p.z(), s->topology_.inverse_mass[i]);
  }
  s->pin_index_.assign(s->topology_.pinned.begin(), s->topology_.pinned.end());
  s->pin_target_.resize(s->pin_index_.size());
  for (size_t k = 0; k < s->pin_index_.size(); ++k) s->pin_target_[k] = s->topology_.rest_positions[s->pin_index_[k]];
  s->pin_target4_.resize(s->pin_index_.size());
  s->group_offsets_.push_back(0);
  const GarmentTopology& t = s->topology_;
  const DistanceConstraints* kinds[3] = {&t.stretch, &t.shear, &t.bend};
  for (int slot = 0; slot < 3; ++slot) {  // the CPU solver's order (kDistanceKindOrder, xpbd_solver.h)
    appendGroups(*kinds[kDistanceKindOrder[slot]], false, t.inverse_mass, s->constraints_, s->group_offsets_);
    if (slot < 2) s->kind_end_[slot] = static_cast<uint32_t>(s->group_offsets_.size() - 1);
  }
  s->distance_groups_ = static_cast<uint32_t>(s->group_offsets_.size() - 1);
  s->group_offsets_.push_back(static_cast<uint32_t>(s->constraints_.size()));
  appendGroups(t.tether, true, t.inverse_mass, s->constraints_, s->group_offsets_);
  s->tether_groups_ = static_cast<uint32_t>(s->group_offsets_.size()) - s->distance_groups_ - 2;
  // The rim edges after the tethers (DrapeClGarment::rim_group_offset): collided, not projected.
  s->rim_group_offset_ = static_cast<uint32_t>(s->group_offsets_.size());
  s->group_offsets_.push_back(static_cast<uint32_t>(s->constraints_.size()));
  appendGroups(t.rims, false, t.inverse_mass, s->constraints_, s->group_offsets_);
  s->rim_groups_ = static_cast<uint32_t>(s->group_offsets_.size()) - s->rim_group_offset_ - 1;
  std::string perr;
  if (!s->setParams(XpbdParams{}, perr) || !s->allocate(err)) {
    if (err.empty()) err = perr;
    return nullptr;
  }
  return s;
}

ClXpbdSolver::~ClXpbdSolver() {
  for (cl_kernel k : {frame_, transform_, normals_kernel_})
    if (k) clReleaseKernel(k);
  for (cl_mem* m : {&work_buf_, &tri_buf_, &face_offset_buf_, &vertex_face_buf_, &garment_, &x_buf_, &prev_buf_, &v_buf_, &span_start_buf_, &pin_start_buf_, &pin_index_buf_,
                    &pin_target_buf_, &constraint_buf_, &group_buf_, &mask_buf_, &shape_buf_, &bounds_buf_,
                    &stats_buf_})
    release(*m);
}

bool ClXpbdSolver::allocate(std::string& err) {
  cl_context ctx = runtime_->context();
  const size_t n = std::max<size_t>(1, particleCount());
  const size_t pins = std::max<size_t>(1, pin_index_.size());
  cl_int rc = CL_SUCCESS;
  auto make = [&](cl_mem& m, size_t bytes) {
    if (rc != CL_SUCCESS) return;
    m = clCreateBuffer(ctx, CL_MEM_READ_WRITE, bytes, nullptr, &rc);
  };
  make(garment_, sizeof(DrapeClGarment));
  make(x_buf_, 2 * n * 16);  // positions, then the frame's normals (when asked for)
  make(prev_buf_, n * 16);
  make(v_buf_, n * 16);
  make(span_start_buf_, n * 16);
  make(pin_start_buf_, pins * 16);
  make(pin_index_buf_, pins * 4);
  make(pin_target_buf_, pins * 16);
  make(constraint_buf_, std::max<size_t>(1, constraints_.size()) * sizeof(DrapeClConstraint));
  make(group_buf_, group_offsets_.size() * 4);
  make(mask_buf_, n);
  make(stats_buf_, sizeof(DrapeClStats));
  shape_capacity_ = 64;
  bounds_capacity_ = 16;
  make(shape_buf_, shape_capacity_ * sizeof(DrapeClShape));
  make(bounds_buf_, bounds_capacity_ * 16);
  if (rc != CL_SUCCESS) {
    err = std::string("OpenCL buffer allocation failed (") + clErrorName(rc) + ")";
    return false;
  }
  const std::pair<cl_kernel*, const char*> kernels[] = {
      {&frame_, "drape_xpbd_frame"}, {&transform_, "drape_transform"}, {&normals_kernel_, "drape_vertex_normals"}};
  for (const auto& k : kernels) {
    if (rc == CL_SUCCESS) *k.first = clCreateKernel(runtime_->program(), k.second, &rc);
    if (rc != CL_SUCCESS) *k.first = nullptr;
  }
  if (rc != CL_SUCCESS) {
    err = std::string("clCreateKernel failed (") + clErrorName(rc) + ")";
    return false;
  }
  if (!phases_.create(runtime_->program(), err)) return false;
  phase_plan_.clear(1);
  phase_plan_.setGarment(0, static_cast<uint32_t>(particleCount()), static_cast<uint32_t>(pin_index_.size()),
                         group_offsets_, distance_groups_, tether_groups_);
  phase_plan_.finish();
  make(work_buf_, phase_plan_.work().size() * 4);
  if (!normal_tables_.append(topology_.triangles, particleCount())) {
    err = "a triangle index is out of range";
    return false;
  }
  make(tri_buf_, std::max<size_t>(1, normal_tables_.indices.size()) * 4);
  make(face_offset_buf_, normal_tables_.face_offsets.size() * 4);
  make(vertex_face_buf_, std::max<size_t>(1, normal_tables_.vertex_faces.size()) * 4);
  const cl_mem args[] = {garment_, x_buf_, prev_buf_, v_buf_, span_start_buf_, pin_start_buf_, pin_index_buf_,
                         pin_target_buf_, constraint_buf_, group_buf_, mask_buf_, shape_buf_, bounds_buf_,
                         stats_buf_};
  for (cl_uint i = 0; i < 14 && rc == CL_SUCCESS; ++i) rc = clSetKernelArg(frame_, i, sizeof(cl_mem), &args[i]);
  // Static data once: pin indices, group table, masks (0xFF: every group when none given).
  std::vector<uint8_t> masks(masks_);
  masks.resize(n, 0xFF);
  std::vector<uint32_t> pin_index(pin_index_);
  pin_index.resize(pins, 0);
  cl_command_queue q = runtime_->queue();
  if (rc == CL_SUCCESS) rc = clEnqueueWriteBuffer(q, pin_index_buf_, CL_TRUE, 0, pins * 4, pin_index.data(), 0, nullptr, nullptr);
  if (rc == CL_SUCCESS)
    rc = clEnqueueWriteBuffer(q, group_buf_, CL_TRUE, 0, group_offsets_.size() * 4, group_offsets_.data(), 0, nullptr, nullptr);
  if (rc == CL_SUCCESS) rc = clEnqueueWriteBuffer(q, mask_buf_, CL_TRUE, 0, n, masks.data(), 0, nullptr, nullptr);
  if (rc == CL_SUCCESS)
    rc = clEnqueueWriteBuffer(q, work_buf_, CL_TRUE, 0, phase_plan_.work().size() * 4, phase_plan_.work().data(), 0,
                              nullptr, nullptr);
  for (const auto& [buffer, table] : {std::pair<cl_mem, const std::vector<uint32_t>*>{tri_buf_, &normal_tables_.indices},
                                      {face_offset_buf_, &normal_tables_.face_offsets},
                                      {vertex_face_buf_, &normal_tables_.vertex_faces}})
    if (rc == CL_SUCCESS && !table->empty())
      rc = clEnqueueWriteBuffer(q, buffer, CL_TRUE, 0, table->size() * 4, table->data(), 0, nullptr, nullptr);
  if (rc != CL_SUCCESS) {
    err = std::string("OpenCL setup failed (") + clErrorName(rc) + ")";
    return false;
  }
  if (!uploadState()) {
    err = device_error_;
    return false;
  }
  return true;
}

bool ClXpbdSolver::upload(cl_mem buffer, const void* data, size_t bytes, std::vector<cl_event>* events) {
  if (bytes == 0) return true;
  cl_event e = nullptr;
  const cl_int rc = clEnqueueWriteBuffer(runtime_->queue(), buffer, events ? CL_FALSE : CL_TRUE, 0, bytes, data, 0,
                                         nullptr, events ? &e : nullptr);
  if (rc != CL_SUCCESS) {
    device_error_ = std::string("clEnqueueWriteBuffer failed (") + clErrorName(rc) + ")";
    return false;
  }
  if (events) events->push_back(e);
  return true;
}

bool ClXpbdSolver::uploadState() {
  normals_valid_ = false;
  flushTransform();  // then overwritten: the device ends as the host copy, as before deferral
  if (particleCount() == 0) return true;
  const size_t bytes = particleCount() * 16;
  v_stale_ = false;
  return upload(x_buf_, x_.data(), bytes, nullptr) && upload(v_buf_, v_.data(), bytes, nullptr);
}

bool ClXpbdSolver::pushPositions() {
  normals_valid_ = false;
  flushTransform();  // the velocities still need it
  if (particleCount() == 0) return true;
  return upload(x_buf_, x_.data(), particleCount() * 16, nullptr);
}


bool ClXpbdSolver::setParams(const XpbdParams& p, std::string& error) {
  XpbdSolver probe{GarmentTopology{}};  // the CPU solver's validation, message for message
  if (!probe.setParams(p, error)) return false;
  params_ = p;  // the compliances reach the device as each frame's alpha~ (prepareFrame)
  return true;
}

bool ClXpbdSolver::setPinTargets(const Vec3* targets, size_t count, std::string& error) {
  if (count != pin_target_.size() || (count > 0 && targets == nullptr)) {
    error = "expected " + std::to_string(pin_target_.size()) + " pin targets, got " + std::to_string(count);
    return false;
  }
  for (size_t k = 0; k < count; ++k) {
    if (!isFinite(targets[k])) {
      error = "pin target " + std::to_string(k) + " is not finite";
      return false;
    }
  }
  for (size_t k = 0; k < count; ++k) pin_target_[k] = targets[k];
  return true;
}

bool ClXpbdSolver::setColliderMotion(const Ellipsoid* start, const Ellipsoid* end, int count, float margin_m,
                                     const std::vector<uint8_t>& groups, std::string& error) {
  // ColliderMotion::set's checks, so both backends reject the same input.
  ColliderMotion probe;
  EllipsoidCollider dummy;
  if (!probe.set(&dummy, start, end, count, margin_m, error)) return false;
  motion_start_.assign(start, start + count);
  motion_end_.assign(end, end + count);
  motion_margin_ = margin_m;
  groups_ = groups;
  return true;
}

void ClXpbdSolver::transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale) {
  normals_valid_ = false;
  const Vec3 shift = pivot + t;
  for (size_t i = 0; i < particleCount(); ++i) x_[i].head<3>() = R * (Vec3(x_[i].head<3>()) - pivot) + shift;
  if (!v_stale_)
    for (size_t i = 0; i < particleCount(); ++i) v_[i].head<3>() = velocity_scale * (R * Vec3(v_[i].head<3>()));
  for (Vec3& p : pin_target_) p = R * (p - pivot) + shift;
  if (particleCount() == 0) return;
  // The device copy moves at the next device use (flushTransform), so that a batched frame can
  // move every garment in one launch (ClFrameBatch); one transform waits at a time.
  flushTransform();
  DrapeClTransform& m = pending_transform_;
  m.r0 = DclF4{R(0, 0), R(1, 0), R(2, 0), 0};
  m.r1 = DclF4{R(0, 1), R(1, 1), R(2, 1), 0};
  m.r2 = DclF4{R(0, 2), R(1, 2), R(2, 2), 0};
  m.pivot = DclF4{pivot.x(), pivot.y(), pivot.z(), 0};
  m.shift = DclF4{shift.x(), shift.y(), shift.z(), 0};
  m.vscale = velocity_scale;
  m.offset = 0;
  m.count = static_cast<uint32_t>(particleCount());
  transform_pending_ = true;
}

void ClXpbdSolver::flushTransform() {
  if (!transform_pending_) return;
  transform_pending_ = false;
  const DrapeClTransform& m = pending_transform_;
  const cl_uint n = m.count;
  cl_int rc = clSetKernelArg(transform_, 0, sizeof(cl_mem), &x_buf_);
  rc |= clSetKernelArg(transform_, 1, sizeof(cl_mem), &v_buf_);
  rc |= clSetKernelArg(transform_, 2, sizeof(cl_uint), &n);
  rc |= clSetKernelArg(transform_, 3, 16, &m.r0);
  rc |= clSetKernelArg(transform_, 4, 16, &m.r1);
  rc |= clSetKernelArg(transform_, 5, 16, &m.r2);
  rc |= clSetKernelArg(transform_, 6, 16, &m.pivot);
  rc |= clSetKernelArg(transform_, 7, 16, &m.shift);
  rc |= clSetKernelArg(transform_, 8, sizeof(float), &m.vscale);
  const size_t wg = 64, global = (particleCount() + wg - 1) / wg * wg;
  if (rc == CL_SUCCESS) {
    rc = clEnqueueNDRangeKernel(runtime_->queue(), transform_, 1, nullptr, &global, &wg, 0, nullptr, nullptr);
    runtime_->countLaunches();
  }
  if (rc != CL_SUCCESS) {
    // Keep host and device consistent: the host copy (already moved) goes to the device.
    device_error_ = std::string("transform kernel failed (") + clErrorName(rc) + ")";
    uploadState();
  }
}

bool ClXpbdSolver::reset(const Vec3* positions, size_t count, std::string& error) {
  if (count != particleCount() || positions == nullptr) {
    error = "expected " + std::to_string(particleCount()) + " positions, got " + std::to_string(count);
    return false;
  }
  for (size_t i = 0; i < count; ++i) {
    if (!isFinite(positions[i])) {
      error = "position " + std::to_string(i) + " is not finite";
      return false;
    }
  }
  for (size_t i = 0; i < count; ++i) {  // w from the topology too (as XpbdSolver::reset)
    x_[i] = Eigen::Vector4f(positions[i].x(), positions[i].y(), positions[i].z(), topology_.inverse_mass[i]);
    v_[i].setZero();
  }
  for (size_t k = 0; k < pin_target_.size(); ++k) pin_target_[k] = positions[pin_index_[k]];
  if (!uploadState()) {
    error = device_error_;
    return false;
  }
  return true;
}

bool ClXpbdSolver::setState(const Eigen::Vector4f* x, const Eigen::Vector4f* v, size_t count, std::string& error) {
  if (count != particleCount() || x == nullptr || v == nullptr) {
    error = "expected " + std::to_string(particleCount()) + " particles";
    return false;
  }
  for (size_t i = 0; i < count; ++i) {
    if (!x[i].allFinite() || !v[i].allFinite()) {
      error = "particle " + std::to_string(i) + " is not finite";
      return false;
    }
  }
  for (size_t i = 0; i < count; ++i) {
    x_[i].head<3>() = x[i].head<3>();
    v_[i] = Eigen::Vector4f(v[i].x(), v[i].y(), v[i].z(), 0.0f);
  }
  for (size_t k = 0; k < pin_target_.size(); ++k) pin_target_[k] = x_[pin_index_[k]].head<3>();
  if (!uploadState()) {
    error = device_error_;
    return false;
  }
  return true;
}

const Eigen::Vector4f* ClXpbdSolver::velocities() const {
  if (v_stale_ && particleCount() > 0) {
    const_cast<ClXpbdSolver*>(this)->flushTransform();  // the device copy is then the current one
    if (clEnqueueReadBuffer(runtime_->queue(), v_buf_, CL_TRUE, 0, particleCount() * 16, v_.data(), 0, nullptr,
                            nullptr) == CL_SUCCESS)
      v_stale_ = false;
  }
  return v_.data();
}


void ClXpbdSolver::setRimGate(const std::vector<uint8_t>& on) {
  const size_t n = particleCount();
  const std::vector<float>& inv_mass = topology_.inverse_mass;
  bool changed = false;
  for (size_t k = group_offsets_[rim_group_offset_]; k < constraints_.size(); ++k) {
    DrapeClConstraint& c = constraints_[k];
    const bool open = on.size() != n || (on[c.a] && on[c.b]);
    const float w = open ? inv_mass[c.a] + inv_mass[c.b] : 0.0f;  // appendGroups' w_sum while open
    if (c.w_sum == w) continue;
    c.w_sum = w;
    changed = true;
  }
  if (!changed) return;
  constraints_dirty_ = true;
  ++constraints_version_;
}

}  // namespace drape
