// The XPBD cloth step on an OpenCL device: XpbdSolver (cloth/xpbd_solver.h) with the same
// parameters, pins, colliders and answers (within float rounding: docs/opencl.md states the
// tolerance), the whole frame in one launch. Per frame: one upload of the frame's pin targets
// and collision shapes (every span's interpolated ellipsoids) plus the step's scalars, one kernel
// launch running every substep (one work-group, particles in __local memory when they fit,
// barriers between colour groups), one readback of the positions and the collision counters.
// Velocities and the previous positions stay on the device; velocities() reads them on demand.
#pragma once

#include "backends/opencl/cl_normals.h"
#include "backends/opencl/cl_phase_launch.h"
#include "backends/opencl/cl_runtime.h"
#include "cloth/xpbd_solver.h"
#include "drape_cl_types.h"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

namespace drape {

// A frame's collision counters as the device left them (DrapeClStats), in the CPU's form.
inline CollisionStats toCollisionStats(const DrapeClStats& s) {
  CollisionStats c;
  c.tests = s.tests;
  c.contacts = s.contacts;
  c.swept_catches = s.swept_catches;
  c.escapes = s.escapes;
  return c;
}

// Per-frame split of the last step (device profiling when the queue has it, else wall clock).
struct ClStepTimings {
  double upload_ns = 0.0;    // host -> device writes (shapes, pins, the garment record)
  double kernel_ns = 0.0;    // the frame kernel (every substep)
  double readback_ns = 0.0;  // positions + counters back to the host
  double host_ns = 0.0;      // host work: shape interpolation and packing
};

class ClXpbdSolver {
 public:
  // Null + err when the device cannot hold the garment (allocation fails). masks: one byte per
  // particle (collision groups) or empty; groups: bit per ellipsoid, or empty (see
  // EllipsoidCollider::setGroups). The state starts at the topology's rest positions, at rest.
  static std::unique_ptr<ClXpbdSolver> create(std::shared_ptr<ClRuntime> runtime, GarmentTopology topology,
                                              std::vector<uint8_t> masks, std::vector<uint8_t> groups,
                                              std::string& err);
  ~ClXpbdSolver();
  ClXpbdSolver(const ClXpbdSolver&) = delete;
  ClXpbdSolver& operator=(const ClXpbdSolver&) = delete;

  // As XpbdSolver.
  bool setParams(const XpbdParams& params, std::string& error);
  const XpbdParams& params() const { return params_; }
  bool setPinTargets(const Vec3* targets, size_t count, std::string& error);
  // groups: the collider's ellipsoid groups for these ellipsoids (EllipsoidCollider::groups()),
  // applied with the particle masks given at creation; empty: every particle meets every one.
  bool setColliderMotion(const Ellipsoid* start, const Ellipsoid* end, int count, float margin_m,
                         const std::vector<uint8_t>& groups, std::string& error);
  void transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale);
  bool reset(const Vec3* positions, size_t count, std::string& error);
  // Positions and velocities (xyzw, as XpbdSolver) in one go: moving a running garment over.
  bool setState(const Eigen::Vector4f* x, const Eigen::Vector4f* v, size_t count, std::string& error);
  // False (state unchanged) on bad arguments, or when the device fails (err() says why; the
  // state is then the last good one).
  bool step(float dt, int substeps = XpbdSolver::kDefaultSubsteps);
  // step() in two halves, so that several garments' frames can run in one launch
  // (ClFrameBatch): prepareFrame() is the host half (validation, this frame's shapes, pin
  // targets and garment record; false on bad arguments, nothing prepared), runPreparedFrame()
  // the device half for this garment alone. ClFrameBatch::run replaces the second for a batch.
  bool prepareFrame(float dt, int substeps);
  bool runPreparedFrame();
  bool framePrepared() const { return prepared_; }

  size_t particleCount() const { return topology_.particleCount(); }
  const GarmentTopology& topology() const { return topology_; }
  const Eigen::Vector4f* positions() const { return x_.data(); }
  // Writable xyz between steps (keep w); pushPositions() then sends them to the device.
  Eigen::Vector4f* mutablePositions() {
    normals_valid_ = false;
    return x_.data();
  }
  bool pushPositions();
  const Eigen::Vector4f* velocities() const;  // read from the device on demand
  // Vertex normals on the device (docs/opencl.md, "Normals"). requestNormals(): the host wants
  // normals, so the next frame runs drape_vertex_normals on its new positions and reads them
  // back with the positions (the same transfer). deviceNormals(): those of the current
  // positions (xyz, w = 0), or null when the last frame ran without them or the positions have
  // changed since (the caller then computes them on the CPU).
  void requestNormals() { normals_requested_ = true; }
  const Eigen::Vector4f* deviceNormals() const { return normals_valid_ ? normals_.data() : nullptr; }
  const CollisionStats& lastCollisionStats() const { return collision_stats_; }
  const ClStepTimings& lastTimings() const { return timings_; }
  const std::string& lastError() const { return device_error_; }
  bool usesLocalMemory() const { return !usesPhases() && particleCount() <= runtime_->localParticles(); }
  // How a frame runs. Auto: one work-group launch (drape_xpbd_frame) for small garments (at most
  // ClRuntime::workGroupMaxParticles: fitting in __local memory, 4 096 on a CPU device, 1 200 on
  // a GPU), else one launch per phase over global memory (drape_phase_*: every compute unit takes
  // part). The two give bit-identical results (tested). The limits are measured (docs/opencl.md):
  // on PoCL the phases win from ~7 800 particles, on an H100 from ~1 100-1 300.
  enum class Path { Auto, WorkGroup, Phases };
  void setPath(Path p) { path_ = p; }
  // The rim gate (XpbdSolver::setRimGate): a rim edge is tested when its two particles are on
  // (empty: every edge). Carried to the device in the rim records' w_sum (0: off), which the rim
  // pass does not otherwise read; the records are uploaded again when it changes.
  void setRimGate(const std::vector<uint8_t>& on);
  bool usesPhases() const {
    return path_ == Path::Phases ||
           (path_ == Path::Auto && particleCount() > runtime_->workGroupMaxParticles());
  }
  const ClRuntime& runtime() const { return *runtime_; }

 private:
  ClXpbdSolver() = default;
  bool allocate(std::string& err);
  bool upload(cl_mem buffer, const void* data, size_t bytes, std::vector<cl_event>* events);
  bool uploadState();  // x_, v_ (and prev) to the device

  std::shared_ptr<ClRuntime> runtime_;
  GarmentTopology topology_;
  XpbdParams params_;
  std::vector<uint8_t> masks_, groups_;
  std::vector<DrapeClConstraint> constraints_;  // distance groups, tether groups, then the rims
  std::vector<uint32_t> group_offsets_;          // distance groups + 1, tether groups + 1, rim groups + 1
  uint32_t distance_groups_ = 0, tether_groups_ = 0;
  uint32_t rim_group_offset_ = 0, rim_groups_ = 0;  // the rim edges' colours in group_offsets_
  uint32_t kind_end_[2] = {0, 0};  // distance group index where the 1st / 2nd kind ends (DrapeClGarment)
  bool constraints_dirty_ = true;  // not on the device yet
  uint64_t constraints_version_ = 0;  // counts setRimGate's changes (a batch re-uploads on a new one)

  std::vector<Eigen::Vector4f> x_;
  std::vector<cl_event> writes_, runs_, reads_;   // stepDevice scratch (events of one frame)
  std::vector<Eigen::Vector4f> readback_;        // stepDevice scratch (positions, then normals)
  mutable std::vector<Eigen::Vector4f> v_;
  mutable bool v_stale_ = false;
  std::vector<Vec3> pin_target_;
  std::vector<uint32_t> pin_index_;
  std::vector<DclF4> pin_target4_;
  std::vector<Ellipsoid> motion_start_, motion_end_;
  float motion_margin_ = 0.0f;
  std::vector<DrapeClShape> shapes_;
  std::vector<DclF4> bounds_;

  friend class ClFrameBatch;
  DrapeClGarment frame_g_{};         // the prepared frame's record (offsets: this garment alone)
  bool prepared_ = false;
  uint64_t batch_id_ = 0;            // unique per solver in the process (a batch's layout key)

  // transform()'s device half, deferred to the next device use (or done for a whole batch by
  // ClFrameBatch with drape_transform_batch): same arithmetic either way.
  void flushTransform();
  DrapeClTransform pending_transform_{};
  bool transform_pending_ = false;

  bool enqueuePhases(std::vector<cl_event>& runs);
  Path path_ = Path::Auto;
  cl_kernel frame_ = nullptr, transform_ = nullptr;
  // The per-phase kernels (large garments) over a table of this one garment; its work rows
  // (static: they depend on the topology only) in work_buf_.
  ClPhaseKernels phases_;
  ClPhasePlan phase_plan_;
  cl_mem work_buf_ = nullptr;
  // Normals: the mesh's vertex -> triangle tables (static), the kernel, the last frame's
  // normals. x_buf_ holds 2 n float4: positions, then the normals the frame computed.
  bool enqueueNormals();
  ClNormalTables normal_tables_;
  cl_kernel normals_kernel_ = nullptr;
  cl_mem tri_buf_ = nullptr, face_offset_buf_ = nullptr, vertex_face_buf_ = nullptr;
  std::vector<Eigen::Vector4f> normals_;
  bool normals_requested_ = false, normals_frame_ = false, normals_valid_ = false;
  cl_mem garment_ = nullptr, x_buf_ = nullptr, prev_buf_ = nullptr, v_buf_ = nullptr,
         span_start_buf_ = nullptr, pin_start_buf_ = nullptr, pin_index_buf_ = nullptr,
         pin_target_buf_ = nullptr, constraint_buf_ = nullptr, group_buf_ = nullptr,
         mask_buf_ = nullptr, shape_buf_ = nullptr, bounds_buf_ = nullptr, stats_buf_ = nullptr;
  size_t shape_capacity_ = 0, bounds_capacity_ = 0;

  CollisionStats collision_stats_;
  ClStepTimings timings_;
  std::string device_error_;
};

}  // namespace drape
