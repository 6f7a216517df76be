#include "cloth/garment_sim.h"
#include "cloth/garment_solver.h"

#include "body/arm_clearance.h"
#include "body/mesh_metrics.h"
#include "cloth/cloth_stats.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace drape {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// Frames of settling and of dressing run at this rate (the recording rate of a Kinect).
constexpr float kSettleFrameS = 1.0f / 30.0f;
// A host step shorter than this simulates this much cloth time: the solvers' velocities are
// (x - x_prev) / h, and a substep of a few nanoseconds turns float rounding of the positions into
// metres per second (a denormal h overflowed 1/h to infinity and 0 * inf poisoned the state;
// found by fuzz_capi with dt = 6.3e-41 s). 10 us of cloth time is invisible.
constexpr float kMinStepS = 1e-5f;
// Dressing starts with the body at this fraction of its size (see GarmentSim::create).
constexpr float kDressStartScale = 0.6f;
// Soft choice of skinning segment (as the OBJ fit's default): see cloth/ring_skin.h.
constexpr float kSkinBlendM = 0.015f;

// out[k] = rest[k] with its radii scaled by s (out has rest's size).
void scaleEllipsoids(const std::vector<Ellipsoid>& rest, float s, std::vector<Ellipsoid>& out) {
  for (size_t k = 0; k < out.size() && k < rest.size(); ++k) {
    out[k] = rest[k];
    out[k].radii *= s;
    out[k].refresh();
  }
}

// A pelvis rotation beyond kPoseJumpRad + kMaxSpinRadPerS * dt in one step is no human motion.
constexpr float kPoseJumpRad = 1.0f;          // 57 degrees
constexpr float kMaxSpinRadPerS = 12.566f;    // two turns a second


Mat3 partialRotation(const Mat3& R, float fraction) {
  Quat q(R);
  q.normalize();
  return Quat::Identity().slerp(fraction, q).toRotationMatrix();
}

}  // namespace

std::string validate(const GarmentSimParams& p) {
  std::ostringstream s;
  auto range = [&](const char* name, float v, float lo, float hi) {
    if (!s.str().empty()) return;
    if (!std::isfinite(v)) s << name << " is not finite";
    else if (v < lo || v > hi) s << name << " = " << v << " is outside [" << lo << ", " << hi << "]";
  };
  range("substep_hz", p.substep_hz, 30.0f, 20000.0f);
  range("max_substeps", static_cast<float>(p.max_substeps), 1.0f, 1000.0f);
  range("max_step_s", p.max_step_s, 1e-4f, 1.0f);
  range("collision_margin_m", p.collision_margin_m, 0.0f, 0.05f);
  range("linear_inertia", p.linear_inertia, 0.0f, 1.0f);
  range("angular_inertia", p.angular_inertia, 0.0f, 1.0f);
  range("blend_in_s", p.blend_in_s, 0.0f, 2.0f);
  range("static_friction", p.xpbd.collision.static_friction, 0.0f, 10.0f);
  range("kinetic_friction", p.xpbd.collision.kinetic_friction, 0.0f, 10.0f);
  if (!s.str().empty()) return s.str();
  if (p.xpbd.collision.response != ContactResponse::Radial &&
      p.xpbd.collision.response != ContactResponse::Exact)
    return "contact response is not radial (0) or exact (1)";
  std::string err;
  XpbdSolver probe_x(GarmentTopology{});
  if (!probe_x.setParams(p.xpbd, err)) return err;
  MassSpringSolver probe_m(GarmentTopology{});
  if (!probe_m.setParams(p.mass_spring, err)) return err;
  return {};
}

// The two solvers behind one face: what GarmentSim needs of either.
// struct GarmentSim::Solver: cloth/garment_solver.h (shared with the OpenCL backend).

namespace {

template <class S>
struct SolverOf : GarmentSim::Solver {
  explicit SolverOf(GarmentTopology t) : s(std::move(t)) {}
  bool setPins(const std::vector<Vec3>& pins, std::string& err) override {
    return s.setPinTargets(pins.data(), pins.size(), err);
  }
  bool setMotion(EllipsoidCollider* c, const std::vector<Ellipsoid>& a, const std::vector<Ellipsoid>& b,
                 float margin, std::string& err) override {
    return s.setColliderMotion(c, a.data(), b.data(), static_cast<int>(a.size()), margin, err);
  }
  bool reset(const std::vector<Vec3>& x, std::string& err) override {
    return s.reset(x.data(), x.size(), err);
  }
  void transform(const Mat3& R, const Vec3& pivot, const Vec3& t, float vscale) override {
    s.transform(R, pivot, t, vscale);
  }
  const Eigen::Vector4f* x() const override { return s.positions(); }
  Eigen::Vector4f* mutableX() override { return s.mutablePositions(); }
  const Eigen::Vector4f* v() const override { return s.velocities(); }
  CollisionStats collision() const override { return s.lastCollisionStats(); }
  S s;
};

struct XpbdFace final : SolverOf<XpbdSolver> {
  explicit XpbdFace(GarmentTopology t) : SolverOf(std::move(t)) { s.setTimingEnabled(true); }
  bool setParams(const GarmentSimParams& p, std::string& err) override { return s.setParams(p.xpbd, err); }
  void step(float dt, int n) override { s.step(dt, n); }
  double collideMs() const override { return s.lastTimings().collision_ns * 1e-6; }
  void setRimGate(const std::vector<uint8_t>& on) override { s.setRimGate(on); }
};

struct MassSpringFace final : SolverOf<MassSpringSolver> {
  using SolverOf::SolverOf;
  bool setParams(const GarmentSimParams& p, std::string& err) override {
    MassSpringParams m = p.mass_spring;
    m.gravity = p.xpbd.gravity;
    m.collision = p.xpbd.collision;
    return s.setParams(m, err);
  }
  void step(float dt, int n) override { s.step(dt, n); }  // an explosion restores the state itself
  double collideMs() const override { return s.lastCollideMs(); }
};

std::unique_ptr<GarmentSim::Solver> makeSolver(ClothSolverKind kind, const GarmentTopology& t) {
  if (kind == ClothSolverKind::Xpbd) return std::make_unique<XpbdFace>(t);
  return std::make_unique<MassSpringFace>(t);
}

std::vector<float> flatten(const std::vector<Vec3>& v) {
  std::vector<float> flat(v.size() * 3);
  for (size_t i = 0; i < v.size(); ++i)
    for (int a = 0; a < 3; ++a) flat[3 * i + static_cast<size_t>(a)] = v[i][a];
  return flat;
}

}  // namespace

GarmentSim::~GarmentSim() = default;
GarmentSim& GarmentSim::operator=(GarmentSim&&) noexcept = default;

std::unique_ptr<GarmentSim> GarmentSim::create(const GarmentMesh& mesh, const TopologyParams& topo,
                                               ClothSolverKind solver, const GarmentSimParams& params,
                                               float dress_time_s, const BodyModel& body_rest,
                                               const std::vector<Ellipsoid>& rest_ellipsoids,
                                               const std::vector<uint8_t>& ellipsoid_groups,
                                               std::string& err, bool cut_from_dressed,
                                               TorsoReach torso_reach, Dressing* deferred) {
  if (std::string e = validate(params); !e.empty()) {
    err = e;
    return nullptr;
  }
  if (!std::isfinite(dress_time_s) || dress_time_s < 0.0f || dress_time_s > 10.0f) {
    err = "dress_time_s must be in [0, 10]";
    return nullptr;
  }
  if (mesh.pin_ring.size() != mesh.pinned.size() || mesh.pin_local.size() != mesh.pinned.size()) {
    err = "pinned, pin_ring and pin_local must have the same length";
    return nullptr;
  }
  const int rings = static_cast<int>(body_rest.rings().size());
  for (size_t k = 0; k < mesh.pinned.size(); ++k) {
    if (mesh.pin_ring[k] < 0 || mesh.pin_ring[k] >= rings || !isFinite(mesh.pin_local[k])) {
      err = "attachment " + std::to_string(k) + " names no body ring or is not finite";
      return nullptr;
    }
  }
  TopologyParams tp = topo;
  tp.pinned = mesh.pinned;
  const std::vector<float> flat = flatten(mesh.positions);
  std::unique_ptr<GarmentSim> g(new GarmentSim());
  if (!buildGarmentTopology(flat.data(), mesh.positions.size(), mesh.indices.data(), mesh.indices.size(),
                            tp, g->topology_, err))
    return nullptr;
  if (g->topology_.pinned.size() != mesh.pinned.size()) {
    err = "pinned vertices must be unique";
    return nullptr;
  }
  g->mesh_ = mesh;
  // topology_.pinned is sorted; keep the attachment arrays in the same order.
  std::vector<size_t> order(mesh.pinned.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return mesh.pinned[a] < mesh.pinned[b]; });
  for (size_t k = 0; k < order.size(); ++k) {
    g->mesh_.pinned[k] = mesh.pinned[order[k]];
    g->mesh_.pin_ring[k] = mesh.pin_ring[order[k]];
    g->mesh_.pin_local[k] = mesh.pin_local[order[k]];
  }
  g->shoulders_.bind(body_rest, g->mesh_.positions, g->mesh_.pinned, g->mesh_.pin_ring);
  if (ellipsoid_groups.size() != rest_ellipsoids.size()) {
    err = "one collision group set per ellipsoid expected";
    return nullptr;
  }
  g->base_groups_ = ellipsoid_groups;
  g->groups_ = ellipsoid_groups;
  // Each particle collides with the part it lies nearest on the rest body, with that body's arms
  // clear of the torso as the tracked body's are (body/arm_clearance.h): on the rest rings the
  // hanging upper arm runs inside the torso's side, and the side panels under it, nearer the
  // arm's tube than the torso's, met only the arm and sank into the torso as it moved away.
  // (Not when the tracked bodies keep their rings on the bones: BodyModelParams.)
  const BodyModelParams& tracked = body_rest.params();
  std::vector<RingPose> mask_rings = body_rest.rings();
  if (tracked.tracked_arms_clear_torso) {
    Vec3 unused[2];
    keepArmsOutOfTorso(body_rest, mask_rings, ArmClearance{tracked.arm_torso_clearance_m, 1.0f}, unused);
  }
  // With the arms clear by more than two layers of cloth (this garment's margin each), the upper
  // arm's sleeve cloth meets the torso too (maskFor); closer, the two parts' inflated ellipsoids
  // overlap and would hold it between them (a clearance of 0: 574 particle-frames inside an
  // ellipsoid on Ges01's T-shirt and P99 stretch 19.6 %).
  const bool sleeve_meets_torso =
      tracked.tracked_arms_clear_torso && tracked.arm_torso_clearance_m > 2.0f * params.collision_margin_m;
  g->masks_.resize(g->mesh_.positions.size());
  for (size_t i = 0; i < g->masks_.size(); ++i)
    g->masks_[i] = maskFor(body_rest, mask_rings, g->mesh_.positions[i], torso_reach != TorsoReach::Torso,
                           sleeve_meets_torso);
  g->torso_reach_ = torso_reach;
  g->applyLegGroups();  // legs trusted (the rest body's, where the garment is dressed outside them)
  g->kind_ = solver;
  g->solver_ = makeSolver(solver, g->topology_);
  if (!g->setParams(params, err)) return nullptr;

  g->pelvis_ring_ = body_rest.chainFirstRing(Chain::Torso);
  const RingPose& pr = body_rest.rings()[static_cast<size_t>(g->pelvis_ring_)];
  g->seen_pelvis_c_ = pr.centre;
  g->seen_pelvis_f_ = pr.frame;
  g->pinTargets(body_rest, g->seen_pins_);
  // The recovery's snapshots (keepState) at their size now: filled the first time in the take's
  // first second, they allocated and touched their pages then, 19-31 us a call against 4 us later
  // (1 981 particles, 142 ellipsoids; 90-114 us on a slower day), a spike in three early frames.
  for (KeptState* k : {&g->before_jump_, &g->before_burst_, &g->calm_[0], &g->calm_[1], &g->calm_[2]}) {
    k->x.resize(g->mesh_.positions.size());
    k->pins.resize(g->mesh_.pinned.size());
    k->ellipsoids.resize(rest_ellipsoids.size());
    k->shoulders = g->shoulders_;
  }

  {
    auto origin = std::make_shared<Origin>();
    origin->mesh = mesh;
    origin->topology = topo;
    origin->dress_time_s = dress_time_s;
    origin->rest_rings = body_rest.rings();
    g->origin_ = std::move(origin);
  }

  // Dressing. A garment that starts partly inside the body (an OBJ fitted from another body) is
  // not pushed out in one go, which would tear it where neighbours leave on different sides:
  // the body grows from kDressStartScale of its size to full size over the first half of the
  // dressing time while the cloth is simulated, so collision pushes it out gradually and the
  // constraints keep it whole. Then it settles on the full-size body.
  Dressing local;
  Dressing& d = deferred != nullptr ? *deferred : local;
  d = Dressing{};
  d.frames = std::max(1, static_cast<int>(std::ceil(dress_time_s / kSettleFrameS - 1e-4f)));
  d.grow = std::max(1, d.frames / 2);
  d.cut_from_dressed = cut_from_dressed;
  d.solver = solver;
  d.params = params;
  d.topology = tp;
  if (deferred != nullptr) d.body_copy = std::make_shared<const BodyModel>(body_rest);
  d.body = deferred != nullptr ? d.body_copy.get() : &body_rest;
  d.rest = rest_ellipsoids;
  d.from = rest_ellipsoids;
  d.to = rest_ellipsoids;
  scaleEllipsoids(d.rest, kDressStartScale, d.from);
  if (!g->solver_->reset(g->mesh_.positions, err)) return nullptr;
  GarmentSimParams weightless = params;
  weightless.xpbd.gravity = Vec3::Zero();
  if (cut_from_dressed && !g->solver_->setParams(weightless, err)) return nullptr;
  if (deferred != nullptr) return g;
  if (!g->dress(d, d.frames, err)) return nullptr;
  return g;
}

bool GarmentSim::dress(Dressing& d, int frames, std::string& err) {
  if (d.finished) return true;
  if (d.body == nullptr) {
    err = "no dressing to go on with";
    return false;
  }
  const BodyModel& body_rest = *d.body;
  const int end = std::min(d.frames, d.done_frames + std::max(frames, 0));
  for (; d.done_frames < end; ++d.done_frames) {
    const int f = d.done_frames;
    const float u = std::min(1.0f, static_cast<float>(f + 1) / static_cast<float>(d.grow));
    scaleEllipsoids(d.rest, kDressStartScale + (1.0f - kDressStartScale) * u, d.to);
    runFrame(d.from, d.to, seen_pins_, kSettleFrameS);
    d.from.swap(d.to);
    if (d.cut_from_dressed && f + 1 == d.grow) {
      // Let the cut out to the shape the body gave it, then settle under gravity.
      std::vector<Vec3> shape(particleCount());
      for (size_t i = 0; i < shape.size(); ++i) shape[i] = solver_->x()[i].head<3>();
      const std::vector<float> flat_shape = flatten(shape);
      GarmentTopology cut;
      if (!buildGarmentTopology(flat_shape.data(), shape.size(), mesh_.indices.data(), mesh_.indices.size(),
                                d.topology, cut, err))
        return false;
      topology_ = std::move(cut);
      mesh_.positions = shape;
      pinOffsetsFromPositions(body_rest, mesh_);
      pinTargets(body_rest, seen_pins_);
      solver_ = makeSolver(d.solver, topology_);
      if (!setParams(d.params, err) || !solver_->reset(shape, err)) return false;
    }
  }
  if (d.done_frames < d.frames) return true;
  // Whatever is still inside (pinched) goes out now, without the escape limit.
  std::vector<Vec3> start(particleCount());
  {
    std::vector<Eigen::Vector4f> x(solver_->x(), solver_->x() + particleCount());
    CollisionParams cp = d.params.xpbd.collision;
    cp.max_escape_m = 0.0f;
    collider_.setEllipsoids(d.rest.data(), d.rest.data(), static_cast<int>(d.rest.size()),
                            d.params.collision_margin_m);
    collider_.collide(x.data(), nullptr, x.size(), cp);
    for (size_t i = 0; i < x.size(); ++i) start[i] = x[i].head<3>();
    if (!solver_->reset(start, err)) return false;
  }
  dressed_.resize(start.size());
  for (size_t i = 0; i < start.size(); ++i) dressed_[i] = solver_->x()[i].head<3>();
  for (const Vec3& p : dressed_) {
    if (!isFinite(p)) {
      err = "the garment did not settle (non-finite positions while dressing): check its parameters";
      return false;
    }
  }
  skin_.bind(body_rest, dressed_, kSkinBlendM);
  openings_.bind(mesh_.indices, dressed_, body_rest);
  last_ = GarmentStepStats{};
  d.finished = true;
  d.body = nullptr;
  d.body_copy.reset();
  d.rest.clear();
  d.from.clear();
  d.to.clear();
  return true;
}

std::unique_ptr<GarmentSim> GarmentSim::createTemplate(const GarmentTemplateParams& tmpl, const TopologyParams& topo,
                                                       ClothSolverKind solver, const GarmentSimParams& params,
                                                       float dress_time_s, const BodyModel& body_rest,
                                                       const std::vector<Ellipsoid>& rest_ellipsoids,
                                                       const std::vector<uint8_t>& ellipsoid_groups, std::string& err) {
  GarmentMesh mesh;
  TemplateLayout layout;
  if (!makeGarmentTemplate(body_rest, tmpl, mesh, err, &layout)) return nullptr;
  std::unique_ptr<GarmentSim> g =
      create(mesh, topo, solver, params, dress_time_s, body_rest, rest_ellipsoids, ellipsoid_groups, err, false,
             tmpl.kind == GarmentKind::Trousers ? TorsoReach::Legs : TorsoReach::LegsAndPelvis);
  if (!g) return nullptr;
  auto origin = std::make_shared<Origin>(*g->origin_);
  origin->from_template = true;
  origin->tmpl = tmpl;
  origin->layout = std::move(layout);
  g->origin_ = std::move(origin);
  return g;
}

std::unique_ptr<GarmentSim> GarmentSim::refitted(const BodyModel& body_rest,
                                                 const std::vector<Ellipsoid>& rest_ellipsoids,
                                                 const std::vector<uint8_t>& ellipsoid_groups,
                                                 std::string& err, bool remake_template,
                                                 Dressing* deferred) const {
  const Origin& o = *origin_;
  if (o.rest_rings.size() != body_rest.rings().size()) {
    err = "the new body has another ring layout than the one the garment was made on";
    return nullptr;
  }
  if (o.from_template && remake_template) {
    // The template made again for this body with the first cut's layout: the particles, triangles
    // and attachments of the garment, placed as a template made for this body places them (for a
    // person's own proportions a better cut than carrying the old one by ring skinning:
    // docs/garments.md). Should the body be too unlike the first for the layout, the ring
    // skinning below does it.
    GarmentMesh mesh;
    std::string why;
    // (The replay takes the attachments from the layout; the triangles and the count are checked.)
    if (makeGarmentTemplate(body_rest, o.tmpl, mesh, why, nullptr, &o.layout) && mesh.indices == o.mesh.indices &&
        mesh.positions.size() == o.mesh.positions.size()) {
      // The new cut keeps which cloth meets the legs (a template's torso cloth: createTemplate).
      std::unique_ptr<GarmentSim> g = create(mesh, o.topology, kind_, params_, o.dress_time_s, body_rest,
                                             rest_ellipsoids, ellipsoid_groups, err, false, torso_reach_, deferred);
      if (g) g->origin_ = origin_;
      return g;
    }
  }
  GarmentMesh mesh = o.mesh;
  RingSkin skin;
  skin.bind(body_rest, o.rest_rings, o.mesh.positions, kSkinBlendM);
  skin.place(body_rest, mesh.positions);
  // Attachments keep their ring; their offset from it follows the carried cut (the ring grew or
  // shrank with the body, so the old offset in metres would put the pin inside or off the body).
  pinOffsetsFromPositions(body_rest, mesh);
  std::unique_ptr<GarmentSim> g = create(mesh, o.topology, kind_, params_, o.dress_time_s, body_rest,
                                         rest_ellipsoids, ellipsoid_groups, err, true, torso_reach_, deferred);
  if (g) g->origin_ = origin_;
  return g;
}

void GarmentSim::replaceWith(GarmentSim&& fresh) {
  void* const token = api_token;
  void* const owner = api_owner;
  const uint64_t steps = steps_;
  const uint32_t jumps = jump_restores_, bursts = burst_restores_, refits = refits_;
  *this = std::move(fresh);
  refits_ = refits + 1;
  api_token = token;
  api_owner = owner;
  steps_ = steps;
  jump_restores_ = jumps;
  burst_restores_ = bursts;
}

uint8_t GarmentSim::maskFor(const BodyModel& body, const std::vector<RingPose>& rings, const Vec3& p,
                            bool torso_meets_legs, bool sleeve_meets_torso) {
  float u = 0.0f;
  const int chain = nearestChain(body, rings, p, &u);
  uint8_t mask = maskForChain(chain);
  const bool arm = static_cast<Chain>(chain) == Chain::ArmL || static_cast<Chain>(chain) == Chain::ArmR;
  if (sleeve_meets_torso && arm && u >= kSleeveMeetsTorsoFrom && u <= kSleeveMeetsTorsoTo)
    mask = static_cast<uint8_t>(mask | chainGroup(Chain::Torso));
  if (torso_meets_legs && static_cast<Chain>(chain) == Chain::Torso) {
    // The leg on its side: the nearer thigh ring. One leg only: cloth between the thighs meeting
    // both would be caught between them.
    const Vec3& l = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::LegL))].centre;
    const Vec3& r = body.rings()[static_cast<size_t>(body.chainFirstRing(Chain::LegR))].centre;
    mask = static_cast<uint8_t>(mask | ((p - l).squaredNorm() < (p - r).squaredNorm() ? kTorsoOverLegL : kTorsoOverLegR));
  }
  return mask;
}

void GarmentSim::setLegsTrusted(bool left, bool right) {
  if (left == host_legs_[0] && right == host_legs_[1]) return;  // the usual frame: nothing changed
  const bool now[2] = {left, right};
  for (int side = 0; side < 2; ++side) {
    // Trusted again: the leg may have moved into the torso cloth while it was not met (an
    // inferred leg is guessed anywhere), so its ellipsoids are checked as after a placement.
    if (now[side] && !host_legs_[side] && tracked_) recheck_legs_ |= static_cast<uint8_t>(1u << side);
    host_legs_[side] = now[side];
  }
  applyLegGroups();
}

void GarmentSim::applyLegGroups() {
  const uint8_t legBit[2] = {chainGroup(Chain::LegL), chainGroup(Chain::LegR)};
  const uint8_t overBit[2] = {kTorsoOverLegL, kTorsoOverLegR};
  bool changed = false;
  for (size_t k = 0; k < groups_.size() && k < base_groups_.size(); ++k) {
    uint8_t g = base_groups_[k];
    const bool clear = k >= leg_clear_.size() || leg_clear_[k];
    if (g == kPelvisFillGroups) {
      // The pelvis fill follows both thighs: met like a leg ellipsoid, while both legs are trusted
      // and it is clear, and only by the garments whose torso reaches it (TorsoReach).
      const bool met = torso_reach_ == TorsoReach::LegsAndPelvis && host_legs_[0] && host_legs_[1] && clear;
      g = met ? kPelvisFillGroups : 0;
    }
    for (int side = 0; side < 2; ++side)
      if (clear && host_legs_[side] && (g & legBit[side])) g = static_cast<uint8_t>(g | overBit[side]);
    changed = changed || groups_[k] != g;
    groups_[k] = g;
  }
  if (!changed) return;
  for (size_t i = 0; i < reach_.size(); ++i) reach_groups_[i] = groups_[static_cast<size_t>(reach_[i])];
  collider_.setGroups(reach_.empty() ? groups_ : reach_groups_, masks_.data());
}

bool GarmentSim::torsoClothInside(const Ellipsoid& e, uint8_t over) const {
  const Eigen::Vector4f* x = solver_->x();
  const size_t n = std::min(particleCount(), masks_.size());
  const float r = e.radii.maxCoeff();
  for (size_t i = 0; i < n; ++i) {
    if (!(masks_[i] & over)) continue;
    const Vec3 p = x[i].head<3>();
    if ((p - e.centre).squaredNorm() < r * r && e.implicit(p) < 0.0f) return true;
  }
  return false;
}

void GarmentSim::updateLegClearance(const std::vector<Ellipsoid>& ellipsoids, uint8_t recheck_sides) {
  if (torso_reach_ == TorsoReach::Torso || (unclear_legs_ == 0 && recheck_sides == 0)) return;
  const uint8_t legL = chainGroup(Chain::LegL), legR = chainGroup(Chain::LegR);
  if (leg_clear_.size() != base_groups_.size()) leg_clear_.assign(base_groups_.size(), 1);
  for (size_t k = 0; k < ellipsoids.size(); ++k) {
    const size_t global = reach_.empty() ? k : static_cast<size_t>(reach_[k]);
    if (global >= base_groups_.size()) continue;
    const uint8_t base = base_groups_[global];
    const bool pelvis = base == kPelvisFillGroups;
    if (!pelvis && !(base & (legL | legR))) continue;
    // A leg's ellipsoids hold the torso cloth of their side; the pelvis fill that of both.
    const int side = (base & legL) ? 0 : 1;
    const uint8_t over = pelvis ? kPelvisFillGroups : side == 0 ? kTorsoOverLegL : kTorsoOverLegR;
    const bool recheck = pelvis ? recheck_sides != 0 : ((recheck_sides >> side) & 1u) != 0;
    if (leg_clear_[global] && !recheck) continue;  // met: nothing to decide
    const bool holds = torsoClothInside(ellipsoids[k], over);
    if (holds == !leg_clear_[global]) continue;
    leg_clear_[global] = holds ? 0 : 1;
    unclear_legs_ = holds ? unclear_legs_ + 1 : unclear_legs_ - 1;
  }
  applyLegGroups();
}

uint8_t GarmentSim::maskForChain(int chain) {
  const auto bit = chainGroup;
  switch (static_cast<Chain>(chain)) {
    case Chain::Torso:
    case Chain::Head: return bit(Chain::Torso) | bit(Chain::Head);
    case Chain::ArmL: return bit(Chain::ArmL);
    case Chain::ArmR: return bit(Chain::ArmR);
    case Chain::LegL: return bit(Chain::LegL) | bit(Chain::Torso);
    case Chain::LegR: return bit(Chain::LegR) | bit(Chain::Torso);
    default: return 0xFF;
  }
}

int GarmentSim::nearestChain(const BodyModel& body, const std::vector<RingPose>& rings, const Vec3& p, float* u) {
  // Distance to the body surface, approximated by the tube between consecutive ring centres
  // (rings: the body's, or a copy with its arms moved) with the rings' mean semi-axis.
  float best = std::numeric_limits<float>::infinity();
  int chain = 0;
  for (int c = 0; c < kChainCount; ++c) {
    const int first = body.chainFirstRing(static_cast<Chain>(c)), n = body.chainRingCount(static_cast<Chain>(c));
    for (int r = first; r + 1 < first + n || (n == 1 && r == first); ++r) {
      const RingPose& a = rings[static_cast<size_t>(r)];
      const RingPose& b = rings[static_cast<size_t>(n == 1 ? r : r + 1)];
      const Vec3 ab = b.centre - a.centre;
      const float len2 = ab.squaredNorm();
      const float t = len2 > 1e-12f ? std::clamp((p - a.centre).dot(ab) / len2, 0.0f, 1.0f) : 0.0f;
      const float ra = 0.5f * (a.forward_m + a.side_m), rb = 0.5f * (b.forward_m + b.side_m);
      const float d = (p - (a.centre + t * ab)).norm() - ((1.0f - t) * ra + t * rb);
      if (d < best) {
        best = d;
        chain = c;
        if (u != nullptr) {
          const auto& st = body.stations();
          *u = (1.0f - t) * st[static_cast<size_t>(r)].u + t * st[static_cast<size_t>(n == 1 ? r : r + 1)].u;
        }
      }
    }
  }
  return chain;
}

bool GarmentSim::setParams(const GarmentSimParams& params, std::string& err) {
  if (std::string e = validate(params); !e.empty()) {
    err = e;
    return false;
  }
  if (!solver_->setParams(params, err)) return false;
  params_ = params;
  return true;
}

size_t GarmentSim::particleCount() const { return topology_.particleCount(); }
const Eigen::Vector4f* GarmentSim::positions() const { return solver_->x(); }
const Eigen::Vector4f* GarmentSim::velocities() const { return solver_->v(); }

void GarmentSim::pinTargets(const BodyModel& body, std::vector<Vec3>& out) const {
  out.resize(mesh_.pinned.size());
  for (size_t k = 0; k < out.size(); ++k) {
    const RingPose& r = body.rings()[static_cast<size_t>(mesh_.pin_ring[k])];
    out[k] = r.centre + r.frame * mesh_.pin_local[k];
  }
  shoulders_.shift(body, out);
}

void GarmentSim::runFrame(const std::vector<Ellipsoid>& start, const std::vector<Ellipsoid>& end,
                          const std::vector<Vec3>& pins, float dt) {
  std::string err;
  solver_->setPins(pins, err);
  solver_->setMotion(&collider_, start, end, params_.collision_margin_m, err);
  const float sim = std::clamp(dt, kMinStepS, params_.max_step_s);
  const int n = std::clamp(static_cast<int>(std::ceil(sim * params_.substep_hz - 1e-3f)), 1, params_.max_substeps);
  if (staging_ && solver_->stageStep(sim, n)) {
    staged_ = true;  // the caller runs it (with other garments' frames) before stepEnd()
    staged_substeps_ = n;
    return;
  }
  solver_->step(sim, n);
  addFrameStats(n);
}

void GarmentSim::addFrameStats(int n) {
  last_.substeps += n;
  last_.collide_ms += solver_->collideMs();
  last_.device += solver_->deviceTimes();
  const CollisionStats c = solver_->collision();
  last_.collision.tests += c.tests;
  last_.collision.contacts += c.contacts;
  last_.collision.swept_catches += c.swept_catches;
  last_.collision.escapes += c.escapes;
}

void GarmentSim::carry(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale) {
  solver_->transform(R, pivot, t, velocity_scale);
}

// The first tracked frame (or a NaN reset, or a pose jump with nothing to restore): put the
// dressed garment on the body now, then let it settle on the new pose with the body held still.
void GarmentSim::placeOnBody(const BodyModel& body, const std::vector<Ellipsoid>& ellipsoids) {
  // With a path: skinned onto its first pose (the rest pose where the person stands, which the
  // dressed shape fits), then carried through the others into this one by the ellipsoids.
  const int poses = path_ != nullptr ? path_->poses() : 0;
  solver_->setRimGate({});  // every rim: the garment is put on the body
  const BodyModel* first = &body;
  const std::vector<Ellipsoid>* first_all = &ellipsoids;
  if (poses > 0) path_->at(0, first, first_all);
  skin_.place(*first, scratch3_);
  std::string err;
  solver_->reset(scratch3_, err);
  shoulders_.restart();
  if (poses > 0) {
    path_from_ = pickReachable(*first_all, path_to_);
    updateLegClearance(path_from_, 3);
    for (int i = 1; i <= poses; ++i) {
      const BodyModel* b = &body;
      const std::vector<Ellipsoid>* all = &ellipsoids;
      if (i < poses) path_->at(i, b, all);
      const std::vector<Ellipsoid>& to = i < poses ? pickReachable(*all, path_to_) : ellipsoids;
      pinTargets(*b, pins_);
      runFrame(path_from_, to, pins_, kSettleFrameS);
      path_from_ = to;
    }
    // The way here is not the person's motion: the settle below starts from rest.
    carry(Mat3::Identity(), Vec3::Zero(), Vec3::Zero(), 0.0f);
  }
  // Placed on a pose the legs may already be in (a person seated from the first frame: the
  // shirt's hem through the thighs): a leg ellipsoid that holds torso cloth now meets it only
  // once it holds none (updateLegClearance); pushed out at once, the hem tore.
  updateLegClearance(ellipsoids, 3);
  shoulders_.observe(body, kSettleFrameS);
  pinTargets(body, pins_);
  const int frames = static_cast<int>(std::ceil(params_.blend_in_s / kSettleFrameS - 1e-4f));
  for (int f = 0; f < frames; ++f) runFrame(ellipsoids, ellipsoids, pins_, kSettleFrameS);
  last_.blend_frames = poses + frames;
}

bool GarmentSim::poseJumped(const RingPose& pelvis, float dt) const {
  // The pelvis ring's rotation since the last step. People spin at up to ~2 turns a second (a
  // pirouette); kPoseJumpRad on top covers the tracker's own noise on a short frame.
  const Mat3 R = pelvis.frame * seen_pelvis_f_.transpose();
  const float c = std::clamp(0.5f * (R.trace() - 1.0f), -1.0f, 1.0f);
  return std::acos(c) > kPoseJumpRad + kMaxSpinRadPerS * std::min(dt, params_.max_step_s);
}

void GarmentSim::setReachable(const std::vector<int>& indices) {
  if (indices == reach_) return;
  reach_.clear();
  reach_groups_.clear();
  for (int k : indices) {
    if (k < 0 || static_cast<size_t>(k) >= groups_.size()) continue;  // stale index: ignored
    reach_.push_back(k);
    reach_groups_.push_back(groups_[static_cast<size_t>(k)]);
  }
  collider_.setGroups(reach_.empty() ? groups_ : reach_groups_, masks_.data());
}

const std::vector<Ellipsoid>& GarmentSim::pickReachable(const std::vector<Ellipsoid>& all,
                                                        std::vector<Ellipsoid>& out) const {
  if (reach_.empty()) return all;
  out.resize(reach_.size());
  for (size_t i = 0; i < reach_.size(); ++i) out[i] = all[static_cast<size_t>(reach_[i])];
  return out;
}

void GarmentSim::step(const BodyModel& body, const std::vector<Ellipsoid>& start_all,
                      const std::vector<Ellipsoid>& end_all, float dt, bool teleported) {
  stepBegin(body, start_all, end_all, dt, teleported, false);
  stepEnd();
}

void GarmentSim::runStepFrame(const std::vector<Ellipsoid>& start, const std::vector<Ellipsoid>& end,
                              const std::vector<Vec3>& pins, float dt) {
  // The rim gate: only the rims of openings round a limb that go round it now meet the ellipsoids, so a
  // rim keeps a limb in but never out (an arm already outside its sleeve caught the cuff from
  // outside and dragged it: docs/garments.md, "Rim edges"). The frames of a placement or a
  // restore run with every rim (the garment is dressed, or as it was, then).
  // Every step: marked every fourth step the ASan frame-rate scenario failed (docs/garments.md,
  // "Rim edges": the gate's cost). Against the body at the step's end: against its start (the
  // last step's end, carried) the ASan build's 10 Hz frame-rate scenario tore (docs/garments.md,
  // "The rim gate at the step's start").
  openings_.markOn(solver_->x(), particleCount(), *pending_body_, rim_gate_);
  solver_->setRimGate(rim_gate_);
  staging_ = allow_staging_;
  runFrame(start, end, pins, dt);
  staging_ = false;
}

void GarmentSim::stepBegin(const BodyModel& body, const std::vector<Ellipsoid>& start_all,
                           const std::vector<Ellipsoid>& end_all, float dt, bool teleported, bool allow_staging) {
  allow_staging_ = allow_staging;
  staged_ = false;
  const std::vector<Ellipsoid>& start = pickReachable(start_all, reach_start_);
  const std::vector<Ellipsoid>& end = pickReachable(end_all, reach_end_);
  pending_t0_ = Clock::now();
  last_ = GarmentStepStats{};
  if (dt > 0.0f) sim_time_s_ += dt;
  pins_.resize(mesh_.pinned.size());
  const RingPose& pr = body.rings()[static_cast<size_t>(pelvis_ring_)];
  pending_body_ = &body;
  pending_end_ = &end;
  if (tracked_) {
    updateLegClearance(start, recheck_legs_);
    recheck_legs_ = 0;
  }
  const bool burst_ended = tracked_ && noiseBurstEnded();
  if (!tracked_ || host_pose_jump_ || poseJumped(pr, dt)) {
    // First frame, or a pose no body reaches in dt from the last one (a skeleton flipped upside
    // down for a frame): the garment is put where the body's rings carry its dressed shape.
    last_.teleport_reset = tracked_;
    if (!tracked_ || !restoreState(before_jump_, body, pr, end)) {
      if (tracked_) keepBeforeJump(start);
      placeOnBody(body, end);
    } else {
      updateLegClearance(end, 3);
      ++jump_restores_;
    }
    tracked_ = true;
    runStepFrame(end, end, pins_, dt);
  } else if (teleported) {
    // The person is somewhere else in the same pose: move the garment with them, at rest.
    last_.teleport_reset = true;
    carry(pr.frame * seen_pelvis_f_.transpose(), seen_pelvis_c_, pr.centre - seen_pelvis_c_, 0.0f);
    shoulders_.observe(body, dt);
    pinTargets(body, pins_);
    runStepFrame(end, end, pins_, dt);
  } else if (burst_ended && restoreState(before_burst_, body, pr, end)) {
    // A burst of sensor noise ended: the garment as it was before it, swept to this pose.
    ++burst_restores_;
    runStepFrame(end, end, pins_, dt);
  } else {
    // Inertia scaling: the part of the pelvis' rigid motion the garment does not feel moves it.
    // The body's start-of-step ellipsoids are carried by the same transform, so garment and body
    // start the step together and only the rest of the motion happens across the substeps
    // (carrying the garment alone would push the trailing side of it into the body).
    shoulders_.observe(body, dt);
    const float fl = 1.0f - params_.linear_inertia, fa = 1.0f - params_.angular_inertia;
    if (fl > 0.0f || fa > 0.0f) {
      const Mat3 R = partialRotation(pr.frame * seen_pelvis_f_.transpose(), fa);
      const Vec3 t = fl * (pr.centre - seen_pelvis_c_);
      carry(R, seen_pelvis_c_, t, 1.0f);
      // Centre and rotation only: the colliders (ColliderMotion, the OpenCL shapes) read centre,
      // radii and rotation, not refresh()'s cache (to_unit and bounds are left stale).
      carried_start_.resize(start.size());
      for (size_t k = 0; k < start.size(); ++k) {
        Ellipsoid& e = carried_start_[k];
        e = start[k];
        e.centre = R * (e.centre - seen_pelvis_c_) + seen_pelvis_c_ + t;
        e.rotation = R * e.rotation;
      }
      pinTargets(body, pins_);
      runStepFrame(carried_start_, end, pins_, dt);
    } else {
      pinTargets(body, pins_);
      runStepFrame(start, end, pins_, dt);
    }
  }
  allow_staging_ = false;
  begin_ms_ = msSince(pending_t0_);
}

void GarmentSim::stepEnd() {
  const Clock::time_point end_t0 = Clock::now();
  const bool was_staged = staged_;
  // The staged frame (if any) has run: its statistics now, as runFrame counts an unstaged one.
  if (staged_) addFrameStats(staged_substeps_);
  staged_ = false;
  const BodyModel& body = *pending_body_;
  const std::vector<Ellipsoid>& end = *pending_end_;
  const RingPose& pr = body.rings()[static_cast<size_t>(pelvis_ring_)];
  // NaN guard (cannot happen with validated input; if it does, never hand NaN to the host). The
  // positions only: a device solver keeps its velocities on the device (reading them would cost
  // a transfer every frame), and a non-finite velocity shows in the next step's positions, where
  // placeOnBody's reset repairs everything, inverse masses and velocities included.
  const Eigen::Vector4f* x = solver_->x();
  for (size_t i = 0; i < particleCount(); ++i) {
    if (!x[i].allFinite()) {
      placeOnBody(body, end);
      last_.nan_reset = true;
      break;
    }
  }
  seen_pelvis_c_ = pr.centre;
  seen_pelvis_f_ = pr.frame;
  keepCalmState(pr);
  ++steps_;
  // The garment's own time: its stepBegin (where a CPU frame runs) and this. The context steps
  // every garment's stepBegin before any stepEnd, so the time in between is the others' frames;
  // a staged device frame ran in the batched launch in between, which it counts whole.
  last_.total_ms = was_staged ? msSince(pending_t0_) : begin_ms_ + msSince(end_t0);
}

const std::vector<Vec3>& GarmentSim::normals() const {
  // A device solver's normals of these positions, computed with its frame (docs/opencl.md).
  if (const Eigen::Vector4f* dn = solver_->deviceNormals()) {
    normals_.resize(particleCount());
    for (size_t i = 0; i < normals_.size(); ++i) normals_[i] = dn[i].head<3>();
    return normals_;
  }
  normal_positions_.resize(particleCount());
  const Eigen::Vector4f* x = solver_->x();
  for (size_t i = 0; i < normal_positions_.size(); ++i) normal_positions_[i] = x[i].head<3>();
  normals_.resize(normal_positions_.size());
  vertexNormals(normal_positions_, mesh_.indices, normals_);
  return normals_;
}

GarmentAccuracy GarmentSim::measure(const std::vector<Ellipsoid>& ellipsoids, const TriangleBvh* bvh,
                                    const BodyModel* body) const {
  GarmentAccuracy a;
  std::vector<float> scratch;
  const Eigen::Vector4f* x = solver_->x();
  a.stretch = stretchStats(topology_, x, scratch);
  constexpr float kInsideTol = 1e-4f;
  for (size_t i = 0; i < particleCount(); ++i) {
    if (!(x[i].w() > 0.0f)) continue;
    const Vec3 p = x[i].head<3>();
    for (size_t k = 0; k < ellipsoids.size(); ++k) {
      if (k < groups_.size() && !(groups_[k] & masks_[i])) continue;  // not one it collides with
      const Ellipsoid& e = ellipsoids[k];
      if (!containsPoint(e.bounds_min, e.bounds_max, p)) continue;
      const Vec3 q = e.toUnit(p);
      const float r = q.norm();
      // Depth along the ray from the centre (an upper bound of the true depth): (1 - r) * |p - c| / r.
      if (r < 1.0f && (1.0f - r) * (p - e.centre).norm() > kInsideTol * std::max(r, 1e-6f)) {
        ++a.proxy_inside;
        break;
      }
    }
  }
  if (bvh != nullptr && !bvh->empty()) {
    // Inside by the winding number, not the pseudo-normal sign: the body mesh intersects itself
    // at the shoulder stitches and the crotch bridge, where that sign misreads points outside.
    // All particles in one call (TriangleBvh::depthsInside: one grid of the body's triangles
    // instead of a tree walk per particle, the same depths).
    std::vector<Vec3> points(particleCount());
    for (size_t i = 0; i < points.size(); ++i) points[i] = x[i].head<3>();
    scratch.assign(points.size(), 0.0f);
    bvh->depthsInside(points.data(), points.size(), scratch.data());
    size_t deep = 0, inside = 0;
    for (float& depth : scratch) {
      depth *= 1000.0f;
      if (depth > 2.0f) ++deep;
      if (depth > 0.0f) ++inside;
    }
    if (!scratch.empty()) {
      const size_t k = std::min(scratch.size() - 1, static_cast<size_t>(std::ceil(0.99 * static_cast<double>(scratch.size()))) - 1);
      std::nth_element(scratch.begin(), scratch.begin() + static_cast<long>(k), scratch.end());
      a.body_penetration_p99_mm = scratch[k];
      a.body_penetration_max_mm = *std::max_element(scratch.begin(), scratch.end());
      a.deeper_than_2mm = static_cast<float>(deep) / static_cast<float>(scratch.size());
      a.inside_body = static_cast<float>(inside) / static_cast<float>(scratch.size());
    }
  }
  if (body != nullptr) a.openings = openings_.count(x, particleCount(), *body);
  return a;
}

bool GarmentSim::replaceSolver(const SolverFactory& make, std::string& err) {
  if (kind_ != ClothSolverKind::Xpbd) {
    err = "only the XPBD solver has another backend (the mass-spring solver runs on the CPU)";
    return false;
  }
  std::unique_ptr<Solver> next = make(topology_, solver_->x(), solver_->v(), masks_, err);
  if (!next || !next->setParams(params_, err)) return false;
  solver_ = std::move(next);
  return true;
}

bool GarmentSim::useCpuSolver(std::string& err) {
  if (backend() == GarmentBackend::Cpu) return true;
  // Only the XPBD solver runs elsewhere (replaceSolver), so the way back is an XPBD solver.
  auto next = std::make_unique<XpbdFace>(topology_);
  std::vector<Vec3> x(particleCount());
  for (size_t i = 0; i < x.size(); ++i) x[i] = solver_->x()[i].head<3>();
  if (!next->setParams(params_, err) || !next->reset(x, err)) return false;
  // The device's velocities carry over (velocities() reads them back): the cloth keeps moving.
  if (!next->s.setVelocities(solver_->v(), particleCount())) {
    err = "the garment's velocities are not finite";
    return false;
  }
  solver_ = std::move(next);
  return true;
}

GarmentBackend GarmentSim::backend() const { return solver_->backend(); }

bool GarmentSim::deviceFailed(std::string* err) const { return solver_->deviceFailed(err); }

}  // namespace drape
