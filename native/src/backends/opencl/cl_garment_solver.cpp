#include "backends/opencl/cl_garment_solver.h"

#include "backends/opencl/cl_frame_batch.h"
#include "backends/opencl/cl_xpbd_solver.h"
#include "cloth/garment_solver.h"

#include <algorithm>
#include <atomic>

namespace drape {
namespace {

struct ClXpbdFace final : GarmentSim::Solver {
  explicit ClXpbdFace(std::unique_ptr<ClXpbdSolver> solver) : s(std::move(solver)) {}

  bool setParams(const GarmentSimParams& p, std::string& err) override { return s->setParams(p.xpbd, err); }
  bool setPins(const std::vector<Vec3>& pins, std::string& err) override {
    return s->setPinTargets(pins.data(), pins.size(), err);
  }
  bool setMotion(EllipsoidCollider* c, const std::vector<Ellipsoid>& a, const std::vector<Ellipsoid>& b,
                 float margin, std::string& err) override {
    static const std::vector<uint8_t> kNone;
    return s->setColliderMotion(a.data(), b.data(), static_cast<int>(a.size()), margin, c ? c->groups() : kNone, err);
  }
  void step(float dt, int substeps) override {
    flush();
    timed = true;
    // A device failure leaves the last good state; the context then moves the garment to the CPU.
    if (!s->step(dt, substeps) && !s->lastError().empty()) {
      failed = true;
      error = s->lastError();
    }
  }
  void setRimGate(const std::vector<uint8_t>& on) override { s->setRimGate(on); }
  bool stageStep(float dt, int substeps) override {
    flush();
    staged = s->prepareFrame(dt, substeps);  // false: bad arguments, nothing runs (as step())
    return true;
  }
  // The staged frame alone (runStagedClFrames batches the others).
  void runStaged() {
    staged = false;
    timed = true;
    if (!s->runPreparedFrame() && !s->lastError().empty()) fail(s->lastError());
  }
  void fail(const std::string& why) {
    failed = true;
    error = why;
  }
  bool reset(const std::vector<Vec3>& x, std::string& err) override {
    dirty = false;
    return s->reset(x.data(), x.size(), err);
  }
  void transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float vscale) override {
    flush();
    s->transform(R, pivot, t, vscale);
  }
  const Eigen::Vector4f* x() const override { return s->positions(); }
  Eigen::Vector4f* mutableX() override {
    dirty = true;  // the caller may write: the device gets the positions before the next use
    return s->mutablePositions();
  }
  const Eigen::Vector4f* v() const override { return s->velocities(); }
  const Eigen::Vector4f* deviceNormals() override {
    s->requestNormals();  // the next frames compute them on the device
    return s->deviceNormals();
  }
  CollisionStats collision() const override { return s->lastCollisionStats(); }
  // Collision runs inside the frame kernel with the rest of the step: no separate time. 0, so the
  // stats' integrate_ms (step minus collide) holds the whole device frame (docs/opencl.md, drape.h).
  double collideMs() const override { return 0.0; }
  DeviceFrameTimes deviceTimes() const override {
    if (!timed) return {};
    const ClStepTimings& t = s->lastTimings();
    return DeviceFrameTimes{t.upload_ns * 1e-6, t.kernel_ns * 1e-6, t.readback_ns * 1e-6, t.host_ns * 1e-6};
  }
  GarmentBackend backend() const override { return GarmentBackend::OpenCl; }
  bool deviceFailed(std::string* err) const override {
    if (failed && err) *err = error;
    return failed;
  }

  void flush() {
    if (dirty && !s->pushPositions()) {
      failed = true;
      error = s->lastError();
    }
    dirty = false;
  }

  std::unique_ptr<ClXpbdSolver> s;
  bool dirty = false, failed = false, staged = false;
  bool timed = false;  // the last frame ran alone (step, runStaged): lastTimings() is its split
  std::string error;
};

}  // namespace

namespace {
std::atomic<bool> g_batching{true};
}  // namespace

void setClFrameBatching(bool on) { g_batching = on; }
bool clFrameBatching() { return g_batching.load(); }

size_t runStagedClFrames(const std::vector<GarmentSim*>& garments) {
  // Group the staged device frames by runtime; a group's frames run as one batch when there are
  // two or more (one frame launch for the one-work-group garments, one launch per phase for the
  // large ones), a lone garment alone.
  std::vector<std::pair<ClRuntime*, std::vector<ClXpbdFace*>>> by_runtime;
  for (GarmentSim* g : garments) {
    auto* face = g ? dynamic_cast<ClXpbdFace*>(g->solverFace()) : nullptr;
    if (!face || !face->staged) continue;
    ClRuntime* rt = const_cast<ClRuntime*>(&face->s->runtime());
    auto it = std::find_if(by_runtime.begin(), by_runtime.end(), [&](const auto& p) { return p.first == rt; });
    if (it == by_runtime.end()) {
      by_runtime.emplace_back(rt, std::vector<ClXpbdFace*>{});
      it = by_runtime.end() - 1;
    }
    it->second.push_back(face);
  }
  size_t batched = 0;
  for (auto& [rt, faces] : by_runtime) {
    std::vector<ClXpbdFace*> together;
    for (ClXpbdFace* f : faces) {
      if (f->s->particleCount() > 0) {
        together.push_back(f);
      } else {
        f->runStaged();
      }
    }
    if (together.size() < 2 || !clFrameBatching()) {
      for (ClXpbdFace* f : together) f->runStaged();
      continue;
    }
    std::vector<ClXpbdSolver*> solvers;
    for (ClXpbdFace* f : together) solvers.push_back(f->s.get());
    std::string err;
    const bool ok = rt->frameBatch().run(solvers, err);
    for (ClXpbdFace* f : together) {
      f->staged = false;
      f->timed = false;  // a batch's frame is timed as a whole, not per garment
      if (!ok) f->fail(err);
    }
    if (ok) batched += together.size();
  }
  return batched;
}

GarmentSim::SolverFactory clGarmentSolverFactory(std::shared_ptr<ClRuntime> runtime) {
  return [runtime](const GarmentTopology& t, const Eigen::Vector4f* x, const Eigen::Vector4f* v,
                   const std::vector<uint8_t>& masks, std::string& err) -> std::unique_ptr<GarmentSim::Solver> {
    std::unique_ptr<ClXpbdSolver> s = ClXpbdSolver::create(runtime, t, masks, {}, err);
    if (!s || !s->setState(x, v, t.particleCount(), err)) return nullptr;
    return std::make_unique<ClXpbdFace>(std::move(s));
  };
}

}  // namespace drape
