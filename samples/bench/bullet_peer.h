// The peer in the same run: Bullet's soft-body cloth (Debian libbullet-dev, 3.24) dressed in the
// same T-shirt mesh on the same body, replayed over the same take at the same frame rate.
//
// A Drape context runs alongside as the driver, at one of Drape's settings (peerDrivers()): it
// tracks the body, builds the tracking ellipsoids and the body mesh, and its garment gives the
// attachment targets (its pinned particles end every step at their targets) and the starting shape
// (the garment dressed at that setting and placed on the first tracked pose). Bullet's stretch
// follows the shirt it starts from (a point less from a less stretched one: docs/benchmarks.md,
// "Bullet inherits the driver's shirt"), so each Drape setting is compared with Bullet started
// from that setting's own shirt. Bullet gets: a soft body made from the garment's rest positions and
// triangles (links from the edges, bending constraints at distance 2, the same mass: 0.2 kg/m^2),
// its attached nodes as kinematic nodes moved to the same targets across the substeps, each
// tracking ellipsoid as a kinematic btMultiSphereShape (one unit sphere, scaled by the radii) moved
// across the substeps (Bullet derives its velocity from pose to pose, which its contacts and
// friction use), friction at Drape's kinetic coefficient (Bullet multiplies the soft body's kDF by
// the rigid body's friction: 0.4 x 1), gravity, 4 mm collision margin (Drape's), `substeps` fixed
// substeps per 1/60 s and `iterations` position iterations. Bullet's soft body meets a rigid shape
// through a sparse signed-distance field sampled on a voxel grid (btSparseSdf), 0.25 m by default:
// sized for metre-scale objects, it is coarser than a forearm (4 cm radius) and lets a quarter of
// the garment sink into the body; `sdf_voxel_m` sets it (kBulletFieldM by default,
// docs/benchmarks.md, "The Bullet peer's distance field"). Bullet: its stepSimulation calls are
// timed; Drape: its whole frame (push + step: skeleton, body, proxies, cloth) beside it, in the
// same frame; both in thread CPU time (and wall time).
// Both garments are measured by the same meters (metrics.h) on the same frames (all but the first).
#pragma once

#include "scenario.h"

#include <cstdint>
#include <string>
#include <vector>

namespace bench {

struct PeerSide {
  std::vector<double> ms;        // per frame: Bullet's stepSimulation / Drape's garment step (cloth only)
  std::vector<double> frame_ms;  // Drape only: push + whole step (skeleton, body, proxies, cloth)
  // Thread CPU time per frame: Bullet's stepSimulation calls; Drape's push + whole step. The
  // ratio is taken from these (wall time on a shared machine penalises the longer step).
  std::vector<double> cpu_ms;
  double stretch_p99 = 0, stretch_max = 0;
  double penetration_p99_mm = 0, penetration_max_mm = 0, deeper_than_2mm = 0;
  double in_body = 0;      // vertex-frames inside the body mesh at any depth
  size_t openings_tracked = 0;  // openings round a body part on the first frame (OpeningsMeter)
  double openings_off = 0;      // frames with one or more of them off it
  double inside_mean = 0;  // free vertices inside any tracking ellipsoid, per frame
  bool finite = true;
};

// The peer's distance-field voxel (m): 5 cm, the coarsest of the sizes measured that keeps the
// shirt on the body (docs/benchmarks.md); Bullet's own default is 0.25 m.
constexpr double kBulletFieldM = 0.05;
constexpr double kBulletDefaultFieldM = 0.25;
// A Drape setting that drives the peer: the library's defaults with these overrides (0 or a
// negative strain limit: the library's default). Bullet starts from that setting's dressed shirt.
struct PeerDriver {
  std::string label;                 // e.g. "default", "strain limit 5 % x 8 passes"
  uint32_t iterations = 0;           // drape_cloth_params.iterations
  float strain_limit = -1.0f;        // drape_cloth_params.strain_limit
  uint32_t strain_limit_passes = 0;  // drape_cloth_params.strain_limit_passes
  bool isDefault() const { return iterations == 0 && strain_limit < 0.0f && strain_limit_passes == 0; }
};
// The setting with less stretch (docs/garments.md, "More strain-limit passes"; Unity's
// DrapeDresser.lessStretch): the strain limit at 5 % in 8 passes.
constexpr float kLessStretchLimit = 0.05f;
constexpr uint32_t kLessStretchPasses = 8;
// 2 iterations per substep with the strain limit at 7 % in 8 passes: of the settings tried, the one
// whose stretch is below Bullet 4 x 10's from its own shirt on both takes by the widest margin
// that keeps the waving sleeve on in drape-replay's scene at 1 900-2 100 particles (docs/benchmarks.md,
// "Each setting against Bullet from its own shirt").
constexpr uint32_t kPeerIterations = 2;
constexpr float kPeerLimit = 0.07f;
constexpr uint32_t kPeerPasses = 8;
// The settings the peer compares with Bullet 4 x 10 on its field, each from its own shirt:
// Drape's default; the strain limit at 5 % in 8 passes; 2 iterations with the limit at 7 % in 8
// passes. The first is the default.
std::vector<PeerDriver> peerDrivers();

struct PeerResult {
  std::string label;  // e.g. "4 x 10 (5 cm field)"
  std::string take;
  double rate_hz = 0;
  int substeps_per_60hz = 0;
  int iterations = 0;
  double sdf_voxel_m = 0;  // Bullet's distance-field voxel
  uint32_t particles = 0;
  PeerDriver driver;  // Drape's setting: drape below, and the shirt Bullet starts from
  PeerSide bullet, drape;
};

// --peer-spread: Bullet's free nodes start shifted together this far (metres, a direction drawn
// per seed) from where Drape placed them: a cloth replay with contacts is chaotic, so each seed is
// another sample of what Bullet does on the take (docs/benchmarks.md, "Bullet over several
// starting shirts"). A rigid shift, not noise per node: noise would stretch the edges at the start.
constexpr double kStartShiftM = 0.0005;

// True when this drape-bench was built with Bullet.
bool bulletAvailable();
// Runs one Bullet setting beside Drape at `driver`, Bullet starting from that setting's shirt.
// start_seed > 0: Bullet's free nodes start shifted by kStartShiftM in a direction drawn from that
// seed (the label says so); Drape is unchanged. false + error on failure.
bool runBulletPeer(const Take& take, uint32_t particles, int substeps_per_60hz, int iterations, double sdf_voxel_m,
                   const PeerDriver& driver, PeerResult& out, std::string& error, uint32_t start_seed = 0);

}  // namespace bench
