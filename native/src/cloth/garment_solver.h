// The face every cloth solver shows GarmentSim (the XPBD and mass-spring CPU solvers in
// garment_sim.cpp, the OpenCL XPBD solver in backends/opencl): what a garment needs of a solver.
#pragma once

#include "cloth/garment_sim.h"

#include <string>
#include <vector>

namespace drape {

struct GarmentSim::Solver {
  virtual ~Solver() = default;
  virtual bool setParams(const GarmentSimParams& p, std::string& err) = 0;
  virtual bool setPins(const std::vector<Vec3>& pins, std::string& err) = 0;
  virtual bool setMotion(EllipsoidCollider* c, const std::vector<Ellipsoid>& a,
                         const std::vector<Ellipsoid>& b, float margin, std::string& err) = 0;
  virtual void step(float dt, int substeps) = 0;
  // Batching (GarmentSim::stepBegin): a solver that can run its frame later together with other
  // garments' prepares it and returns true; the caller runs it before reading the state. False
  // (the CPU solvers): step() runs now.
  virtual bool stageStep(float /*dt*/, int /*substeps*/) { return false; }
  // The rim edges to collide from the next step on (XpbdSolver::setRimGate): one byte per particle,
  // empty for all. Solvers without rim collision ignore it.
  virtual void setRimGate(const std::vector<uint8_t>& /*on*/) {}
  virtual bool reset(const std::vector<Vec3>& x, std::string& err) = 0;
  virtual void transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float vscale) = 0;
  virtual const Eigen::Vector4f* x() const = 0;
  virtual Eigen::Vector4f* mutableX() = 0;  // xyz writable between steps
  virtual const Eigen::Vector4f* v() const = 0;
  // Vertex normals the solver computed with its last frame for the current positions (xyz,
  // w = 0), or null: GarmentSim::normals() then computes them on the CPU. A call also says the
  // host reads normals, so a device solver computes them with its next frames (docs/opencl.md).
  virtual const Eigen::Vector4f* deviceNormals() { return nullptr; }
  virtual CollisionStats collision() const = 0;
  virtual double collideMs() const = 0;
  // A device solver's split of its last frame when that frame ran on its own; zero for the CPU
  // solvers and for a frame that ran batched with other garments' (timed as a whole, not per
  // garment).
  virtual DeviceFrameTimes deviceTimes() const { return {}; }
  // Backends (docs/opencl.md): which one runs the step, and for a device solver whether its
  // device failed (the garment then goes back to the CPU with `error` as the reason).
  virtual GarmentBackend backend() const { return GarmentBackend::Cpu; }
  virtual bool deviceFailed(std::string* /*error*/) const { return false; }
};

}  // namespace drape
