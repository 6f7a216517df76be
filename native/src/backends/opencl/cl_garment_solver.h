// The OpenCL XPBD solver behind GarmentSim's solver face (cloth/garment_solver.h): a garment
// switches to it with GarmentSim::replaceSolver(clGarmentSolverFactory(runtime)).
#pragma once

#include "backends/opencl/cl_runtime.h"
#include "cloth/garment_sim.h"

#include <memory>

namespace drape {

GarmentSim::SolverFactory clGarmentSolverFactory(std::shared_ptr<ClRuntime> runtime);

}  // namespace drape
