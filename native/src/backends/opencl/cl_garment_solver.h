// The OpenCL XPBD solver behind GarmentSim's solver face (cloth/garment_solver.h): a garment
// switches to it with GarmentSim::replaceSolver(clGarmentSolverFactory(runtime)).
#pragma once

#include "backends/opencl/cl_runtime.h"
#include "cloth/garment_sim.h"

#include <memory>
#include <vector>

namespace drape {

GarmentSim::SolverFactory clGarmentSolverFactory(std::shared_ptr<ClRuntime> runtime);

// Runs the device frames GarmentSim::stepBegin staged on `garments` (others are skipped): per
// runtime, the one-work-group frames of two or more garments in one batched launch
// (ClFrameBatch), any other alone. A device failure marks the garment's solver failed (the
// context then moves it to the CPU). Returns how many garments ran in a batch.
size_t runStagedClFrames(const std::vector<GarmentSim*>& garments);
// Whether runStagedClFrames batches (default on). Off, every staged frame runs alone, as before
// batching existed: the tests' and the benchmark's one-by-one reference. Process-wide.
void setClFrameBatching(bool on);
bool clFrameBatching();

}  // namespace drape
