// The per-phase frame of large garments (opencl/phases.cl) over a table of garments: one launch
// per phase (per colour group index, per pass, per substep) for every per-phase garment of the
// table, so a batch of large garments costs the launches of one. A garment alone is a table of
// one (ClXpbdSolver), a batch (ClFrameBatch) its whole table: the same kernels, the same bits.
#pragma once

#include "backends/opencl/cl_runtime.h"
#include "drape_cl_types.h"

#include <string>
#include <utility>
#include <vector>

namespace drape {

// Which work-item of a launch does what: rows of (garments + 1) exclusive prefixes of item
// counts per garment (phases.cl): particles, pins, each distance colour group index, each
// tether group index. Garments not on the per-phase path count zero everywhere.
class ClPhasePlan {
 public:
  void clear(size_t garments);
  // Garment i of the table runs on the per-phase path: its particle and pin counts and its
  // colour groups' sizes (group_offsets: the solver's table, distance groups + 1 entries then
  // tether groups + 1, offsets into its own constraints).
  void setGarment(size_t i, uint32_t particles, uint32_t pins, const std::vector<uint32_t>& group_offsets,
                  uint32_t distance_groups, uint32_t tether_groups);
  // Builds the rows; call after the last setGarment.
  void finish();

  size_t garments() const { return garments_; }
  bool any() const { return any_; }
  uint32_t distanceGroups() const { return max_distance_; }
  uint32_t tetherGroups() const { return max_tether_; }
  const std::vector<uint32_t>& work() const { return work_; }
  uint32_t items(size_t row) const { return work_[row * (garments_ + 1) + garments_]; }
  // The largest one garment's item count in the row (whether a row is "small" does not depend on
  // how many garments share the launch: the launches per frame do not grow with them).
  uint32_t maxItems(size_t row) const { return max_items_[row]; }

 private:
  size_t garments_ = 0;
  bool any_ = false;
  uint32_t max_distance_ = 0, max_tether_ = 0;
  // Per garment: particles, pins, then its group sizes (distance, tether) as counts.
  std::vector<std::vector<uint32_t>> distance_, tether_;
  std::vector<uint32_t> particles_, pins_;
  std::vector<uint32_t> work_, max_items_;
};

// The device buffers one phase frame reads and writes (the table's layout: offsets into them).
struct ClPhaseBuffers {
  cl_mem table = nullptr, work = nullptr, x = nullptr, prev = nullptr, v = nullptr, span_start = nullptr,
         pin_start = nullptr, pin_index = nullptr, pin_target = nullptr, constraints = nullptr, groups = nullptr,
         masks = nullptr, shapes = nullptr, bounds = nullptr, stats = nullptr;
};

class ClPhaseKernels {
 public:
  ClPhaseKernels() = default;
  ~ClPhaseKernels();
  ClPhaseKernels(const ClPhaseKernels&) = delete;
  ClPhaseKernels& operator=(const ClPhaseKernels&) = delete;

  bool create(cl_program program, std::string& err);
  // Queues the frame of every per-phase garment of `table` (plan.garments() entries, the same
  // as on the device in b.table), without waiting. Consecutive colour groups of at most a
  // work-group's items (per garment) run in one launch of one work-group
  // (drape_phase_project_rows). Substeps and passes run up to the largest of those garments'; the
  // strain limit's passes after each substep that is the last of some garment with it on.
  // first/last (optional): events of the first and the last launch (the kernel time), which the
  // caller releases. CL_SUCCESS or the failing call's code.
  cl_int enqueue(ClRuntime& runtime, const ClPhaseBuffers& b, const ClPhasePlan& plan,
                 const DrapeClGarment* table, cl_event* first, cl_event* last);

 private:
  cl_kernel clear_stats_ = nullptr, pin_start_ = nullptr, predict_ = nullptr, pins_ = nullptr, project_ = nullptr,
            project_rows_ = nullptr, collide_velocity_ = nullptr, rims_ = nullptr;
  // enqueue()'s scratch, kept between frames: the colour groups' launches of a regular pass and
  // of a strain-limit pass.
  std::vector<std::pair<uint32_t, uint32_t>> group_runs_, limit_runs_;
};

}  // namespace drape
