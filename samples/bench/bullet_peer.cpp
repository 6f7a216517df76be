// Built only when CMake finds Bullet (samples/CMakeLists.txt); bullet_absent.cpp otherwise.
#include "bullet_peer.h"

#include "metrics.h"

#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <memory>
#include <random>

#include <time.h>

namespace bench {

namespace {

using Clock = std::chrono::steady_clock;

struct ContextDeleter {
  void operator()(drape_context* c) const { drape_context_destroy(c); }
};

// CPU time of this thread, ms: on a shared machine a 50 ms Bullet step is preempted far more often
// than a 1 ms Drape step, so wall time would favour Drape; both engines run on this thread only.
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

btVector3 bt(const drape_vec3& v) { return btVector3(v.x, v.y, v.z); }

btTransform pose(const drape_ellipsoid& e) {
  const btMatrix3x3 r(e.axis_x.x, e.axis_y.x, e.axis_z.x,  //
                      e.axis_x.y, e.axis_y.y, e.axis_z.y,  //
                      e.axis_x.z, e.axis_y.z, e.axis_z.z);
  return btTransform(r, bt(e.centre));
}

// Bullet's world, owned in the order it must be torn down.
struct World {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  std::vector<std::unique_ptr<btMultiSphereShape>> shapes;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::unique_ptr<btSoftBody> cloth;
  ~World() {
    if (cloth) world.removeSoftBody(cloth.get());
    for (auto& b : bodies) world.removeRigidBody(b.get());
  }
};

// One garment's meters, fed the same frames as the others (the same body surface, ellipsoids and
// pinned vertices), then read into its PeerSide.
struct GarmentMeters {
  StretchMeter stretch;
  PenetrationMeter pen;
  OpeningsMeter openings;
  std::vector<double> inside;
  void addFrame(const BodySurface& body, const drape_vec3* x, size_t n, const std::vector<uint8_t>& pinned,
                const std::vector<drape_ellipsoid>& ellipsoids) {
    pen.addFrame(body, x, n);
    stretch.addFrame(x);
    openings.addFrame(x, ellipsoids);
    inside.push_back(countInsideEllipsoids(x, n, pinned, ellipsoids));
  }
  void finish(PeerSide& side) const {
    readErrors(stretch, pen, inside, side);
    side.openings_tracked = openings.tracked();
    side.openings_off = openings.offFraction();
  }
};

// Frame i of the take into one Drape context: push, step, then its garment's vertices into x.
// cpu_ms: thread CPU time of push + step; frame_ms: their wall time; cloth_ms: the garment step as
// drape_garment_get_stats reports it.
bool pushAndStep(drape_context* ctx, drape_garment* garment, const Take& take, size_t i, std::vector<drape_vec3>& x,
                 double& frame_ms, double& cloth_ms, double& cpu_ms, std::string& error) {
  const drape_skeleton_frame f = skeletonFrame(take, i);
  const Clock::time_point t0 = Clock::now();
  const double c0 = threadCpuMs();
  if (drape_result r = drape_context_push_skeleton(ctx, &f)) return failed("drape_context_push_skeleton", r, error);
  if (drape_result r = drape_context_step(ctx, frameDt(take, i))) return failed("drape_context_step", r, error);
  cpu_ms = threadCpuMs() - c0;
  frame_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  drape_garment_stats gs{};
  gs.struct_size = sizeof gs;
  const uint32_t n = static_cast<uint32_t>(x.size());
  if (!ok("drape_garment_get_stats", drape_garment_get_stats(garment, &gs), error) ||
      !ok("drape_garment_read_mesh", drape_garment_read_mesh(garment, x.data(), nullptr, n, nullptr, 0), error))
    return false;
  cloth_ms = gs.step_ms;
  return true;
}

}  // namespace

bool bulletAvailable() { return true; }

bool runBulletPeer(const Take& take, uint32_t particles, int substeps_per_60hz, int iterations, double sdf_voxel_m,
                   const PeerDriver& driver, PeerResult& out, std::string& error, uint32_t start_seed) {
  out = PeerResult{};
  if (!(sdf_voxel_m >= 0.001 && sdf_voxel_m <= 10.0)) {
    error = "the distance-field voxel must be in [0.001, 10] m";
    return false;
  }
  out.substeps_per_60hz = substeps_per_60hz;
  out.iterations = iterations;
  out.sdf_voxel_m = sdf_voxel_m;
  char field[48];
  std::snprintf(field, sizeof field, " (%g cm field)", 100.0 * sdf_voxel_m);
  out.label = std::to_string(substeps_per_60hz) + " x " + std::to_string(iterations) + field;
  if (start_seed > 0) out.label += ", start seed " + std::to_string(start_seed);
  out.take = take.name;
  out.rate_hz = take.rate_hz;
  out.driver = driver;

  // The driver: Drape at the driver's setting, dressed at it (so Bullet starts from that setting's
  // shirt), but for the garment's cut: Bullet gets the mesh and rest shape Drape starts with, so
  // Drape keeps that cut too (DRAPE_GARMENT_FIT_SHAPE: no refit to the person's skeleton at
  // calibration) and both simulate the same garment.
  drape_context_desc desc;
  drape_context_desc_init(&desc);
  desc.garment_fit = DRAPE_GARMENT_FIT_SHAPE;
  drape_context* raw = nullptr;
  if (drape_result r = drape_context_create(&desc, &raw)) return failed("drape_context_create", r, error);
  std::unique_ptr<drape_context, ContextDeleter> ctx(raw);
  drape_garment_template tmpl;
  drape_garment_template_init(&tmpl);
  tmpl.particles = particles;
  drape_cloth_params cloth;
  drape_cloth_params_init(&cloth);
  if (driver.iterations > 0) cloth.iterations = driver.iterations;
  if (driver.strain_limit >= 0.0f) cloth.strain_limit = driver.strain_limit;
  if (driver.strain_limit_passes > 0) cloth.strain_limit_passes = driver.strain_limit_passes;
  drape_garment* garment = nullptr;
  if (drape_result r = drape_context_add_garment_template(ctx.get(), nullptr, &tmpl, &cloth, &garment))
    return failed("drape_context_add_garment_template", r, error);
  uint32_t nv = 0, ni = 0, ne = 0, body_nv = 0, body_ni = 0;
  if (!ok("drape_garment_get_params", drape_garment_get_params(garment, &cloth), error) ||
      !ok("drape_garment_get_mesh_size", drape_garment_get_mesh_size(garment, &nv, &ni), error) ||
      !ok("drape_context_get_ellipsoid_count", drape_context_get_ellipsoid_count(ctx.get(), &ne), error) ||
      !ok("drape_context_get_body_mesh_size", drape_context_get_body_mesh_size(ctx.get(), &body_nv, &body_ni), error))
    return false;
  out.particles = nv;
  std::vector<uint32_t> indices(ni), body_idx(body_ni);
  std::vector<drape_vec3> rest(nv), x(nv), body(body_nv), bx(nv);
  if (!ok("drape_garment_read_mesh", drape_garment_read_mesh(garment, nullptr, nullptr, 0, indices.data(), ni),
          error) ||
      !ok("drape_garment_read_rest_positions", drape_garment_read_rest_positions(garment, rest.data(), nv), error) ||
      !ok("drape_context_read_body_mesh",
          drape_context_read_body_mesh(ctx.get(), nullptr, nullptr, 0, body_idx.data(), body_ni), error))
    return false;
  std::vector<drape_ellipsoid> e_start(ne), e_end(ne);

  // The driver's frame: its garment, and what Bullet takes from it (ellipsoids, body mesh).
  auto pushStep = [&](size_t i, double& frame_ms, double& cloth_ms, double& cpu_ms) -> bool {
    uint32_t count = 0;
    return pushAndStep(ctx.get(), garment, take, i, x, frame_ms, cloth_ms, cpu_ms, error) &&
           ok("drape_context_read_ellipsoids", drape_context_read_ellipsoids(ctx.get(), e_end.data(), ne, &count),
              error) &&
           ok("drape_context_read_body_mesh",
              drape_context_read_body_mesh(ctx.get(), body.data(), nullptr, body_nv, nullptr, 0), error);
  };
  double frame_ms = 0, cloth_ms = 0, cpu_ms = 0;
  if (!pushStep(0, frame_ms, cloth_ms, cpu_ms)) return false;
  std::vector<uint8_t> pinned(nv, 0);
  {
    const float* xyzw = nullptr;
    uint32_t n = 0;
    if (!ok("drape_garment_view_positions", drape_garment_view_positions(garment, &xyzw, &n), error)) return false;
    for (uint32_t k = 0; k < n && k < nv; ++k) pinned[k] = xyzw[4 * k + 3] == 0.0f;
  }

  // Bullet: the same mesh, mass, body and attachments.
  World w;
  btSoftBodyWorldInfo& info = w.world.getWorldInfo();
  info.m_gravity = bt(cloth.gravity);
  info.air_density = 0;
  info.water_density = 0;
  info.m_sparsesdf.Initialize();
  // The voxel Reset() restores (it runs below whenever a radius changes).
  info.m_sparsesdf.setDefaultVoxelsz(static_cast<btScalar>(sdf_voxel_m));
  info.m_sparsesdf.Reset();
  w.world.setGravity(info.m_gravity);
  std::vector<btScalar> xyz;
  for (const drape_vec3& p : rest) xyz.insert(xyz.end(), {p.x, p.y, p.z});
  std::vector<int> tris(indices.begin(), indices.end());
  w.cloth.reset(btSoftBodyHelpers::CreateFromTriMesh(info, xyz.data(), tris.data(), static_cast<int>(ni / 3), false));
  btSoftBody& sb = *w.cloth;
  btSoftBody::Material* mat = sb.m_materials[0];
  mat->m_kLST = 1.0;  // stiffest links: Drape's stretch is rigid (compliance 0)
  mat->m_kAST = 1.0;
  sb.generateBendingConstraints(2, mat);
  double area = 0.0;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const btVector3 a = bt(rest[indices[t]]), b = bt(rest[indices[t + 1]]), c = bt(rest[indices[t + 2]]);
    area += 0.5 * (b - a).cross(c - a).length();
  }
  sb.setTotalMass(static_cast<btScalar>(0.2 * area), true);  // drape_garment_desc_init: 0.2 kg/m^2
  const double rate = 60.0 * substeps_per_60hz;
  sb.m_cfg.piterations = iterations;
  sb.m_cfg.kDP = static_cast<btScalar>(cloth.damping / rate);  // Drape's 1/s damping per substep
  sb.m_cfg.kDF = cloth.kinetic_friction;
  sb.m_cfg.kCHR = 1.0;
  sb.m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
  sb.getCollisionShape()->setMargin(cloth.collision_margin_m);
  // Start where Drape placed it on the first pose; with a seed, the free nodes all moved by one
  // offset of kStartShiftM in a direction drawn from the seed (a rigid shift: no edge between free
  // nodes changes length, so the start adds no stretch of its own).
  btVector3 offset(0, 0, 0);
  if (start_seed > 0) {
    std::mt19937 rng(start_seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    const btVector3 dir(static_cast<btScalar>(gauss(rng)), static_cast<btScalar>(gauss(rng)),
                        static_cast<btScalar>(gauss(rng)));
    offset = dir.normalized() * static_cast<btScalar>(kStartShiftM);
  }
  for (uint32_t k = 0; k < nv; ++k) {
    if (pinned[k]) sb.setMass(static_cast<int>(k), 0);
    const btVector3 at = pinned[k] ? bt(x[k]) : bt(x[k]) + offset;
    sb.m_nodes[static_cast<int>(k)].m_x = at;
    sb.m_nodes[static_cast<int>(k)].m_q = at;
  }
  w.world.addSoftBody(&sb);
  for (uint32_t k = 0; k < ne; ++k) {
    const btVector3 centre(0, 0, 0);
    const btScalar radius = 1;
    auto shape = std::make_unique<btMultiSphereShape>(&centre, &radius, 1);
    shape->setLocalScaling(bt(e_end[k].radii));
    btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, shape.get());
    ci.m_startWorldTransform = pose(e_end[k]);
    // Bullet's soft-rigid contact takes kDF times the rigid body's friction as its coefficient
    // (btSoftBody's collision callback: fc = m_cfg.kDF * getFriction()): 1 here, so the cloth
    // meets Drape's kinetic friction (kDF above), not its square.
    ci.m_friction = 1.0;
    auto body_rb = std::make_unique<btRigidBody>(ci);
    body_rb->setCollisionFlags(body_rb->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body_rb->setActivationState(DISABLE_DEACTIVATION);
    w.world.addRigidBody(body_rb.get());
    w.shapes.push_back(std::move(shape));
    w.bodies.push_back(std::move(body_rb));
  }

  // Bullet's garment and the driver's.
  GarmentMeters m_bullet, m_drape;
  for (GarmentMeters* m : {&m_bullet, &m_drape}) {
    m->stretch.setMesh(indices, rest);
    m->openings.bind(indices, x.data(), nv, e_end);  // the driver's dressed garment, which both start from
  }
  BodySurface surface;
  std::vector<drape_vec3> pin_start(nv);
  for (size_t i = 1; i < take.frames.size(); ++i) {
    e_start = e_end;
    for (uint32_t k = 0; k < nv; ++k)
      if (pinned[k]) pin_start[k] = x[k];
    if (!pushStep(i, frame_ms, cloth_ms, cpu_ms)) return false;
    out.drape.ms.push_back(cloth_ms);
    out.drape.frame_ms.push_back(frame_ms);
    out.drape.cpu_ms.push_back(cpu_ms);
    const double dt = take.timestamps_s[i] - take.timestamps_s[i - 1];
    const int n = std::max(1, static_cast<int>(std::lround(dt * rate)));
    const btScalar h = static_cast<btScalar>(dt / n);
    // Radii follow the body each frame; Bullet's distance-field cache does not notice a new
    // scaling, so it is cleared when any radius moved by more than 0.1 mm.
    bool rescaled = false;
    for (uint32_t k = 0; k < ne; ++k) {
      const btVector3 r = bt(e_end[k].radii);
      if ((r - w.shapes[k]->getLocalScaling()).length() > 1e-4) {
        w.shapes[k]->setLocalScaling(r);
        rescaled = true;
      }
    }
    const Clock::time_point t0 = Clock::now();
    const double c0 = threadCpuMs();
    if (rescaled) info.m_sparsesdf.Reset();
    for (int s = 0; s < n; ++s) {
      const btScalar t = static_cast<btScalar>(s + 1) / static_cast<btScalar>(n);
      for (uint32_t k = 0; k < ne; ++k) {
        const btTransform a = pose(e_start[k]), b = pose(e_end[k]);
        btTransform now;
        now.setOrigin(a.getOrigin().lerp(b.getOrigin(), t));
        now.setRotation(a.getRotation().slerp(b.getRotation(), t));
        // Only the pose: stepSimulation (saveKinematicState) takes a kinematic body's linear and
        // angular velocity from its last pose to this one, the velocity its contacts and
        // friction see. Setting the velocity here, or the last pose to this one, would be
        // overwritten by, or zero, that velocity.
        w.bodies[k]->setWorldTransform(now);
      }
      for (uint32_t k = 0; k < nv; ++k) {
        if (!pinned[k]) continue;
        btSoftBody::Node& node = sb.m_nodes[static_cast<int>(k)];
        const btVector3 target = bt(pin_start[k]).lerp(bt(x[k]), t);
        node.m_v = (target - node.m_x) / h;
      }
      w.world.stepSimulation(h, 0, h);
    }
    out.bullet.cpu_ms.push_back(threadCpuMs() - c0);
    out.bullet.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    for (uint32_t k = 0; k < nv; ++k) {
      const btVector3& p = sb.m_nodes[static_cast<int>(k)].m_x;
      bx[k] = drape_vec3{static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
      if (!std::isfinite(bx[k].x) || !std::isfinite(bx[k].y) || !std::isfinite(bx[k].z)) out.bullet.finite = false;
    }
    if (!surface.set(body, body_idx)) {
      error = "the body mesh could not be measured";
      return false;
    }
    if (out.bullet.finite) m_bullet.addFrame(surface, bx.data(), nv, pinned, e_end);
    m_drape.addFrame(surface, x.data(), nv, pinned, e_end);
  }
  m_bullet.finish(out.bullet);
  m_drape.finish(out.drape);
  return true;
}

}  // namespace bench
