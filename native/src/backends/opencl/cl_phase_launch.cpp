// ClPhasePlan and ClPhaseKernels: the per-phase frame over a garment table. cl_phase_launch.h.
#include "backends/opencl/cl_phase_launch.h"

#include <algorithm>
#include <utility>

namespace drape {

void ClPhasePlan::clear(size_t garments) {
  garments_ = garments;
  any_ = false;
  max_distance_ = max_tether_ = 0;
  particles_.assign(garments, 0);
  pins_.assign(garments, 0);
  distance_.resize(garments);
  tether_.resize(garments);
  for (size_t i = 0; i < garments; ++i) {
    distance_[i].clear();
    tether_[i].clear();
  }
}

void ClPhasePlan::setGarment(size_t i, uint32_t particles, uint32_t pins, const std::vector<uint32_t>& offsets,
                             uint32_t distance_groups, uint32_t tether_groups) {
  any_ = true;
  particles_[i] = particles;
  pins_[i] = pins;
  distance_[i].clear();
  tether_[i].clear();
  for (uint32_t c = 0; c < distance_groups; ++c) distance_[i].push_back(offsets[c + 1] - offsets[c]);
  const uint32_t t0 = distance_groups + 1;
  for (uint32_t c = 0; c < tether_groups; ++c) tether_[i].push_back(offsets[t0 + c + 1] - offsets[t0 + c]);
  max_distance_ = std::max(max_distance_, distance_groups);
  max_tether_ = std::max(max_tether_, tether_groups);
}

void ClPhasePlan::finish() {
  const size_t rows = 2 + max_distance_ + max_tether_, stride = garments_ + 1;
  work_.assign(rows * stride, 0u);
  max_items_.assign(rows, 0u);
  auto count = [&](size_t row, size_t g) -> uint32_t {
    if (row == 0) return particles_[g];
    if (row == 1) return pins_[g];
    const size_t c = row - 2;
    if (c < max_distance_) return c < distance_[g].size() ? distance_[g][c] : 0u;
    const size_t t = c - max_distance_;
    return t < tether_[g].size() ? tether_[g][t] : 0u;
  };
  for (size_t row = 0; row < rows; ++row) {
    uint32_t sum = 0;
    for (size_t g = 0; g < garments_; ++g) {
      work_[row * stride + g] = sum;
      sum += count(row, g);
      max_items_[row] = std::max(max_items_[row], count(row, g));
    }
    work_[row * stride + garments_] = sum;
  }
}

ClPhaseKernels::~ClPhaseKernels() {
  for (cl_kernel k : {clear_stats_, pin_start_, predict_, pins_, project_, project_rows_, collide_velocity_, rims_})
    if (k) clReleaseKernel(k);
}

bool ClPhaseKernels::create(cl_program program, std::string& err) {
  if (clear_stats_) return true;
  const std::pair<cl_kernel*, const char*> kernels[] = {
      {&clear_stats_, "drape_phase_clear_stats"}, {&pin_start_, "drape_phase_pin_start"},
      {&predict_, "drape_phase_predict"},         {&pins_, "drape_phase_pins"},
      {&project_, "drape_phase_project"},         {&project_rows_, "drape_phase_project_rows"},
      {&collide_velocity_, "drape_phase_collide_velocity"}, {&rims_, "drape_phase_rims"}};
  cl_int rc = CL_SUCCESS;
  for (const auto& k : kernels) {
    *k.first = clCreateKernel(program, k.second, &rc);
    if (rc != CL_SUCCESS) {
      *k.first = nullptr;
      err = std::string("clCreateKernel(") + k.second + ") failed (" + clErrorName(rc) + ")";
      for (const auto& made : kernels)
        if (*made.first) {
          clReleaseKernel(*made.first);
          *made.first = nullptr;
        }
      return false;
    }
  }
  return true;
}

cl_int ClPhaseKernels::enqueue(ClRuntime& runtime, const ClPhaseBuffers& b, const ClPhasePlan& plan,
                               const DrapeClGarment* table, cl_event* first, cl_event* last) {
  cl_command_queue q = runtime.queue();
  cl_int rc = CL_SUCCESS;
  const cl_uint count = static_cast<cl_uint>(plan.garments());
  auto arg = [&](cl_kernel k, cl_uint i, auto v) {
    if (rc == CL_SUCCESS) rc = clSetKernelArg(k, i, sizeof(v), &v);
  };
  // The table's common head: table, count, work.
  for (cl_kernel k : {pin_start_, predict_, pins_, project_, project_rows_, collide_velocity_, rims_}) {
    arg(k, 0, b.table);
    arg(k, 1, count);
    arg(k, 2, b.work);
  }
  arg(clear_stats_, 0, b.stats), arg(clear_stats_, 1, count), arg(clear_stats_, 2, b.work);
  arg(pin_start_, 3, b.x), arg(pin_start_, 4, b.pin_start), arg(pin_start_, 5, b.pin_index);
  arg(predict_, 3, b.x), arg(predict_, 4, b.prev), arg(predict_, 5, b.v), arg(predict_, 6, b.span_start);
  arg(pins_, 3, b.x), arg(pins_, 4, b.pin_start), arg(pins_, 5, b.pin_index), arg(pins_, 6, b.pin_target);
  arg(project_, 3, b.x), arg(project_, 4, b.constraints), arg(project_, 5, b.groups);
  arg(project_rows_, 3, b.x), arg(project_rows_, 4, b.constraints), arg(project_rows_, 5, b.groups);
  arg(collide_velocity_, 3, b.x), arg(collide_velocity_, 4, b.prev), arg(collide_velocity_, 5, b.v),
      arg(collide_velocity_, 6, b.span_start), arg(collide_velocity_, 7, b.masks), arg(collide_velocity_, 8, b.shapes),
      arg(collide_velocity_, 9, b.bounds), arg(collide_velocity_, 10, b.stats);
  arg(rims_, 3, b.x), arg(rims_, 4, b.prev), arg(rims_, 5, b.v), arg(rims_, 6, b.masks), arg(rims_, 7, b.shapes),
      arg(rims_, 8, b.bounds), arg(rims_, 9, b.constraints), arg(rims_, 10, b.groups), arg(rims_, 11, b.stats);
  // Substeps and passes: up to the largest among the per-phase garments.
  int substeps = 0, iterations = 0;
  const std::vector<uint32_t>& work = plan.work();
  for (size_t g = 0; g < plan.garments(); ++g) {
    if (work[g + 1] == work[g]) continue;  // not on the per-phase path (row 0: its particles)
    substeps = std::max(substeps, table[g].substeps);
    iterations = std::max(iterations, table[g].iterations);
  }
  // Whether any per-phase garment collides its rim edges (drape_phase_rims after each collision).
  bool rims = false;
  for (size_t g = 0; g < plan.garments(); ++g) rims = rims || (work[g + 1] != work[g] && table[g].rim_groups > 0);
  // One work-item per item, rounded up to 64; or, with `one_group`, a single work-group.
  const size_t wg = runtime.workGroup();
  auto launch = [&](cl_kernel k, size_t items, bool is_last, bool one_group = false) {
    if (rc != CL_SUCCESS || items == 0) return;
    const size_t global = one_group ? wg : (items + 63) / 64 * 64;
    cl_event* e = (first && !*first) ? first : (is_last ? last : nullptr);
    rc = clEnqueueNDRangeKernel(q, k, 1, nullptr, &global, one_group ? &wg : nullptr, 0, nullptr, e);
    runtime.countLaunches();
  };
  if (first) *first = nullptr;
  if (last) *last = nullptr;
  launch(clear_stats_, count, false);
  launch(pin_start_, plan.items(1), false);
  const uint32_t distance = plan.distanceGroups(), tether = plan.tetherGroups();
  arg(project_rows_, 8, static_cast<cl_uint>(distance));
  // The colour groups' launches, the same every pass and substep: (first group, count), a count
  // above 1 a run of consecutive small groups (rows 2 + c) for one launch of one work-group.
  auto makeRuns = [&](std::vector<std::pair<uint32_t, uint32_t>>& runs, uint32_t from, uint32_t to) {
    runs.clear();
    for (uint32_t c = from; c < to;) {
      uint32_t run = 0;
      while (c + run < to && plan.maxItems(2 + c + run) <= wg) ++run;
      run = run >= 2 ? run : 1;
      runs.emplace_back(c, run);
      c += run;
    }
  };
  makeRuns(group_runs_, 0, distance + tether);
  // The groups' launches of one pass: distance groups, then tether groups (mode 1); with `limit`
  // the strain limit's pass over the runs given (distance groups only, project_rows_ arg 11).
  auto launchRuns = [&](const std::vector<std::pair<uint32_t, uint32_t>>& runs, bool limit) {
    for (const auto& [c, run] : runs) {
      if (run > 1) {
        arg(project_rows_, 6, static_cast<cl_uint>(2 + c));
        arg(project_rows_, 7, static_cast<cl_uint>(run));
        launch(project_rows_, wg, false, true);
        continue;
      }
      const bool is_tether = c >= distance;
      arg(project_, 6, static_cast<cl_uint>(2 + c));
      arg(project_, 7, static_cast<cl_uint>(is_tether ? c - distance : c));
      arg(project_, 8, static_cast<cl_uint>(limit ? DCL_MODE_LIMIT : is_tether ? DCL_MODE_TETHER : DCL_MODE_DISTANCE));
      launch(project_, plan.items(2 + c), false);
    }
  };
  arg(project_rows_, 11, cl_uint{0});
  for (int s = 0; s < substeps; ++s) {
    const cl_int sub = s;
    arg(predict_, 7, sub);
    launch(predict_, plan.items(0), false);
    arg(pins_, 7, sub);
    launch(pins_, plan.items(1), false);
    arg(project_, 9, sub);
    arg(project_rows_, 9, sub);
    for (int it = 0; it < iterations; ++it) {
      arg(project_, 10, static_cast<cl_int>(it));
      arg(project_rows_, 10, static_cast<cl_int>(it));
      launchRuns(group_runs_, false);
    }
    // The strain limit (XpbdParams::strain_limit) after the passes of a substep that is some
    // garment's last, before its collision: up to the most passes among those garments, over the
    // distance groups from the first of their stretch groups (kind_end[1]); the kernels pick, per
    // garment, its own last substep, passes and stretch groups (dcl_projects, phases.cl).
    int limit_passes = 0;
    uint32_t stretch_first = distance;
    for (size_t g = 0; g < plan.garments(); ++g) {
      if (work[g + 1] == work[g] || table[g].substeps != s + 1 || table[g].strain_passes <= 0) continue;
      limit_passes = std::max(limit_passes, table[g].strain_passes);
      stretch_first = std::min(stretch_first, table[g].kind_end[1]);
    }
    if (limit_passes > 0 && stretch_first < distance) {
      makeRuns(limit_runs_, stretch_first, distance);
      arg(project_rows_, 11, cl_uint{1});
      for (int pass = 0; pass < limit_passes; ++pass) {
        arg(project_, 10, static_cast<cl_int>(pass));
        arg(project_rows_, 10, static_cast<cl_int>(pass));
        launchRuns(limit_runs_, true);
      }
      arg(project_rows_, 11, cl_uint{0});
    }
    arg(collide_velocity_, 11, sub);
    launch(collide_velocity_, plan.items(0), s + 1 == substeps && !rims);
    if (rims) {
      arg(rims_, 12, sub);
      launch(rims_, wg, s + 1 == substeps, true);
    }
  }
  return rc;
}

}  // namespace drape
