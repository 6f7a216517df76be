// Energy drift of a free-hanging garment: how much energy the integrator creates or destroys on
// its own, with nothing else (collision, friction, damping, inertia scaling) taking any away.
//
// Precisely: the setting's T-shirt template (its particle count), built on the default body's
// rest pose, hangs from its attachment particles (collar and shoulder seams) held fixed where they
// are at rest; no body, no collision, gravity (0, -9.81, 0) m/s^2, damping, drag and spring
// damping 0, no speed clamp; the setting's solver, substep rate and iterations; 1/60 s frames for
// `seconds`. It starts at rest in its rest shape and falls into a hang. E = kinetic + gravitational
// energy of the free particles (cloth/cloth_stats.h; the constraints store no energy: XPBD's
// stretch is rigid, the springs' elastic energy is left out for both). drift = (E(T) - E(0)) /
// (M |g| H), M the free mass, H the garment's height at rest: the fraction of the garment's own
// potential-energy scale gained (> 0) or lost (< 0) over the run. Exact dynamics give 0 only
// with elastic energy counted; inextensible XPBD loses energy by design (projection is inelastic),
// so this prices how much motion a setting damps numerically.
#pragma once

#include "scenario.h"

#include <string>

namespace bench {

struct EnergyDrift {
  double drift = 0;       // (E(T) - E(0)) / (M g H)
  double worst = 0;       // the largest |E(t) - E(0)| / (M g H) over the frames
  bool exploded = false;  // the mass-spring solver reported an explosion
};

// Uses drape's internal C++ (drape_core): the C ABI exposes neither velocities nor masses.
bool energyDrift(const Setting& s, double seconds, EnergyDrift& out, std::string& error);

}  // namespace bench
