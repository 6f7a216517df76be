#include "energy.h"

#include "capi/context.h"
#include "cloth/cloth_stats.h"
#include "cloth/garment_sim.h"
#include "cloth/garment_templates.h"
#include "cloth/mass_spring_solver.h"
#include "cloth/xpbd_solver.h"

#include <algorithm>
#include <cmath>

namespace bench {

namespace {

template <class Solver>
bool run(Solver& solver, const drape::Vec3& g, int frames, int substeps, double scale, EnergyDrift& out) {
  const drape::GarmentTopology& t = solver.topology();
  const double e0 = drape::clothEnergy(t, solver.positions(), solver.velocities(), g).total();
  for (int f = 0; f < frames; ++f) {
    if (!solver.step(1.0f / 60.0f, substeps)) {
      out.exploded = true;
      return true;
    }
    const double e = drape::clothEnergy(t, solver.positions(), solver.velocities(), g).total();
    out.worst = std::max(out.worst, std::abs(e - e0) / scale);
    out.drift = (e - e0) / scale;
  }
  return true;
}

}  // namespace

bool energyDrift(const Setting& s, double seconds, EnergyDrift& out, std::string& error) {
  out = EnergyDrift{};
  drape_context_desc desc;
  drape_context_desc_init(&desc);
  drape::Context ctx(desc);
  drape::GarmentTemplateParams tp;
  tp.kind = drape::GarmentKind::TShirt;
  tp.target_particles = static_cast<int>(s.particles);
  drape::GarmentMesh mesh;
  if (!drape::makeGarmentTemplate(ctx.restBody(), tp, mesh, error)) return false;
  std::vector<float> xyz;
  for (const drape::Vec3& p : mesh.positions) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  drape::TopologyParams topo;  // the library's defaults, as drape_garment_desc_init gives them
  topo.pinned = mesh.pinned;
  drape::GarmentTopology t;
  if (!drape::buildGarmentTopology(xyz.data(), mesh.positions.size(), mesh.indices.data(), mesh.indices.size(), topo, t,
                                   error))
    return false;
  double mass = 0.0, lo = 1e30, hi = -1e30;
  for (size_t i = 0; i < t.particleCount(); ++i) {
    if (t.inverse_mass[i] == 0.0f) continue;
    mass += t.mass[i];
    lo = std::min<double>(lo, t.rest_positions[i].y());
    hi = std::max<double>(hi, t.rest_positions[i].y());
  }
  const drape::Vec3 g(0.0f, -9.81f, 0.0f);
  const double scale = mass * 9.81 * std::max(hi - lo, 1e-3);
  const int frames = std::max(1, static_cast<int>(std::lround(seconds * 60.0)));
  const int substeps = std::max(1, static_cast<int>(std::ceil(s.substep_hz / 60.0f - 1e-3f)));
  const drape::GarmentSimParams defaults;  // tether slack etc. as garments use them
  if (s.solver == DRAPE_SOLVER_MASS_SPRING) {
    drape::MassSpringParams p = defaults.mass_spring;
    p.gravity = g;
    p.damping = 0.0f;
    p.spring_damping = 0.0f;
    drape::MassSpringSolver solver(t);
    if (!solver.setParams(p, error)) return false;
    return run(solver, g, frames, substeps, scale, out);
  }
  drape::XpbdParams p = defaults.xpbd;
  p.gravity = g;
  p.damping = 0.0f;
  p.drag = 0.0f;
  p.max_speed = 0.0f;
  p.iterations = static_cast<int>(s.iterations);
  p.strain_limit = s.strain_limit;
  p.strain_limit_passes = static_cast<int>(s.strain_limit_passes);
  drape::XpbdSolver solver(t);
  if (!solver.setParams(p, error)) return false;
  return run(solver, g, frames, substeps, scale, out);
}

}  // namespace bench
