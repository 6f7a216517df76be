// Several garments' frames in one launch (docs/opencl.md, "Batching"): the one-work-group frame
// kernel (drape_xpbd_frame) takes a table of garments, work-group i running garment i;
// ClFrameBatch packs the prepared frames of many ClXpbdSolvers on one runtime (one context's
// garments, or several contexts' through drape_step_contexts) into that table and its
// concatenated buffers, so a frame costs one launch, one upload of each per-frame array and one
// readback, whatever the number of garments. Each work-group runs exactly the arithmetic of the
// garment's own launch, so the results are the same bits (tested).
#pragma once

#include "backends/opencl/cl_phase_launch.h"
#include "backends/opencl/cl_xpbd_solver.h"

#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace drape {

class ClFrameBatch {
 public:
  explicit ClFrameBatch(ClRuntime& runtime);
  ~ClFrameBatch();
  ClFrameBatch(const ClFrameBatch&) = delete;
  ClFrameBatch& operator=(const ClFrameBatch&) = delete;

  // Runs the prepared frames (prepareFrame() returned true) of `solvers`, all on this runtime and
  // non-empty: the one-work-group garments (!usesPhases()) in one launch of the frame kernel, the
  // per-phase ones (large garments) in one launch per phase for all of them (ClPhaseKernels:
  // the launches of one large garment, whatever their number). The garments' own
  // device state (positions, velocities) is copied into the batch buffers and back on the device
  // (no host transfer); the per-frame arrays (garment table, pin targets, shapes, span bounds)
  // go up once for the batch, positions and counters come back once. Constraints, the group
  // table, masks and pin indices go up again only when the members or their constraints change.
  // False + err on a device failure: every member then keeps its last good state.
  bool run(const std::vector<ClXpbdSolver*>& solvers, std::string& err);

 private:
  bool grow(cl_mem& buffer, size_t& capacity, size_t bytes, cl_mem_flags flags);
  bool runLocked(const std::vector<ClXpbdSolver*>& solvers, std::string& err);
  cl_int enqueuePhases();

  ClRuntime& runtime_;
  std::mutex mutex_;  // contexts on other threads may share the runtime
  cl_kernel frame_ = nullptr, transform_ = nullptr;  // drape_xpbd_frame, drape_transform_batch
  struct Buffer {
    cl_mem mem = nullptr;
    size_t capacity = 0;
  };
  Buffer garments_, x_, prev_, v_, span_start_, pin_start_, pin_index_, pin_target_, constraints_, groups_,
      masks_, shapes_, bounds_, stats_, transforms_, work_, triangles_, face_offsets_, vertex_faces_;
  // Normals: when a member asked for them (requestNormals), one drape_vertex_normals launch over
  // every member's particles (the tables of all their meshes, static like the constraints), into
  // x_ after the positions, which then come back with them in one readback.
  cl_kernel normals_ = nullptr;
  ClNormalTables normal_tables_;
  // The per-phase garments' launches: the table's work rows (ClPhasePlan), rebuilt per frame.
  ClPhaseKernels phases_;
  ClPhasePlan plan_;
  // run()'s members in table order: the one-work-group garments first (work-group g of the
  // frame kernel = table entry g), then the per-phase ones.
  std::vector<ClXpbdSolver*> members_;
  // The members (solver ids) whose static data the device holds.
  std::vector<uint64_t> layout_;
  std::vector<uint64_t> next_layout_;  // run()'s scratch: this frame's members
  // Host staging of the last run (non-blocking uploads read them until the frame ends).
  std::vector<DrapeClGarment> table_;
  std::vector<DrapeClTransform> transforms_host_;  // the members' deferred rigid carries
  std::vector<DclF4> pin_targets_, bounds_host_;
  std::vector<DrapeClShape> shapes_host_;
  std::vector<DrapeClConstraint> constraints_host_;
  // Each member's constraints_version_ as last uploaded (its rim gate changes its records).
  std::vector<uint64_t> constraint_versions_;
  std::vector<uint32_t> groups_host_, pin_index_host_;
  std::vector<uint8_t> masks_host_;
  std::vector<DrapeClStats> stats_host_;
  std::vector<Eigen::Vector4f> x_host_;
};

}  // namespace drape
