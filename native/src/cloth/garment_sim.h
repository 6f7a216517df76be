// One garment worn by one tracked body: a cloth solver (XPBD by default, the paper's mass-spring
// for comparison) plus what turns a solver into a garment that stays on a moving person:
//  - attachments: pinned particles follow body rings (target = ring centre + frame * local);
//  - collision with the tracking ellipsoids, interpolated from the body of the previous step to
//    this one across the substeps (cloth/collider_motion.h);
//  - a dressing pass at creation: pushed outside the ellipsoids of the rest pose, then settled;
//  - inertia scaling: a fraction of the body's rigid motion (pelvis ring) carries the garment
//    directly instead of through constraints (as NvCloth / Unity Cloth / Chaos do);
//  - the first tracked frame: the dressed garment is placed on the tracked pose by ring skinning
//    (cloth/ring_skin.h) and settles there; a teleport carries it rigidly with the pelvis ring,
//    so nothing stretches across the room;
//  - a NaN guard: a non-finite result restores the dressed shape carried to the current body.
// Host frame times vary: a step of dt runs ceil(dt * substep_hz) substeps (capped).
// Method and figures: docs/garments.md. Nothing throws except std::bad_alloc.
#pragma once

#include "body/body_model.h"
#include "cloth/cloth_stats.h"
#include "cloth/garment_openings.h"
#include "cloth/placement_path.h"
#include "cloth/garment_templates.h"
#include "cloth/garment_topology.h"
#include "cloth/mass_spring_solver.h"
#include "cloth/ring_skin.h"
#include "cloth/shoulder_seams.h"
#include "cloth/xpbd_solver.h"
#include "proxies/collision.h"
#include "proxies/mesh_bvh.h"
#include "proxies/proxy_builder.h"

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace drape {

enum class ClothSolverKind : int { Xpbd = 0, MassSpring = 1 };
// Where a garment's cloth step runs (docs/opencl.md): the CPU solver or an OpenCL device.
enum class GarmentBackend : int { Cpu = 0, OpenCl = 1 };

struct GarmentSimParams {
  // Garments limit the collider's escape step to 1 cm: cloth pinched between touching body parts
  // stays pinched instead of being pulled through one of them (proxies/collision.h).
  // Tethers get 10 % slack: a garment moving round the body (a sleeve on a raised arm) moves
  // particles farther from the collar than they are at rest without stretching any edge, and a
  // hard limit at the rest distance then fights the stretch constraints (docs/garments.md).
  // Collision runs every second substep (150 Hz at the default 300 Hz; the swept test covers the
  // two substeps): collision cost halves and stretch, penetration and particles inside stay
  // within the run-to-run noise on the shared takes; every third substep made the 120 Hz BVH
  // takes (3 substeps a frame) unstable (docs/garments.md). A garment of 300 to 1 250 particles
  // collides every substep (collision_stride 0, collisionStrideFor in cloth/xpbd_solver.h): its
  // coarse sleeves came off the arms (docs/garments.md, "Coarse garments collide every substep").
  // The strain limit (10 %, two passes at the end of each step, XpbdParams::strain_limit): on the
  // shared takes x templates the pooled P99 stretch fell in 37 of 40 runs (geometric mean x 0.82,
  // Ges01 T-shirt 16.2 -> 12.4 %) with the body penetration within the run-to-run noise, for
  // 1.7 % of the frame at 1 809 particles and 5 % at 32 266 (docs/garments.md, "A strain limit at
  // the end of each step").
  GarmentSimParams() {
    xpbd.collision.max_escape_m = 0.01f;
    xpbd.tether_scale = 1.1f;
    xpbd.collision_stride = 0;
    xpbd.strain_limit = 0.1f;
  }

  float substep_hz = 300.0f;    // substeps per simulated second, [30, 20000]
  int max_substeps = 200;       // per step, [1, 1000]; a longer step gets bigger substeps
  float max_step_s = 0.1f;      // a host frame longer than this simulates only this, (0, 1]
  XpbdParams xpbd;              // gravity, compliances, damping, drag, wind, speed clamp, contact
  MassSpringParams mass_spring; // used by the mass-spring solver (its collision: xpbd.collision)
  float collision_margin_m = EllipsoidCollider::kDefaultMargin;  // cloth thickness, [0, 0.05]
  float linear_inertia = 0.5f;  // [0, 1]: 1 = physical, 0 = carried rigidly with the pelvis
  float angular_inertia = 0.5f; // [0, 1]: the same for the pelvis' rotation
  float blend_in_s = 0.3f;      // first frame: settling time after the garment is placed on the
                                // tracked pose by ring skinning, [0, 2]
};
// Empty string when valid, else what is wrong.
std::string validate(const GarmentSimParams& p);

// Where a device frame's time went, from the OpenCL queue's profiling events (docs/opencl.md):
// uploads, the kernels (first launch's start to the last one's end), the readback, and the host's
// packing of the frame. What the step's wall time holds beyond their sum is the host enqueueing
// the launches and waiting for them.
struct DeviceFrameTimes {
  double upload_ms = 0.0, kernel_ms = 0.0, readback_ms = 0.0, host_ms = 0.0;
  DeviceFrameTimes& operator+=(const DeviceFrameTimes& o) {
    upload_ms += o.upload_ms;
    kernel_ms += o.kernel_ms;
    readback_ms += o.readback_ms;
    host_ms += o.host_ms;
    return *this;
  }
};

struct GarmentStepStats {
  int substeps = 0;
  int blend_frames = 0;          // extra frames run to settle on a new pose (first frame, teleport)
  double total_ms = 0.0;         // wall time of the step
  double collide_ms = 0.0;       // of which in the ellipsoid collision
  DeviceFrameTimes device;       // a device solver's frames run on their own, summed (else 0)
  CollisionStats collision;      // summed over the substeps
  bool teleport_reset = false;
  bool nan_reset = false;
};

struct GarmentAccuracy {
  StretchStats stretch;                // structural edges, now
  uint32_t proxy_inside = 0;           // free particles inside (> 0.1 mm) an ellipsoid of their groups
  float body_penetration_p99_mm = 0;   // depth of garment vertices inside the body mesh
  float body_penetration_max_mm = 0;
  float deeper_than_2mm = 0;           // fraction of vertices more than 2 mm inside the body
  float inside_body = 0;               // fraction of vertices inside the body at any depth
  OpeningCount openings;               // openings round a body part at rest, and those off it now
                                       // (cloth/garment_openings.h); 0 / 0 without a body
};

class GarmentSim {
 public:
  // Builds the topology (mesh.pinned attached to mesh.pin_ring/pin_local) and the solver, then
  // dresses the garment on `body_rest` (a BodyModel updated with its rest pose) and the ellipsoids
  // built from it: free particles pushed outside, then `dress_time_s` of settling under gravity.
  // Null + err on bad input (mesh, pins, params).
  // ellipsoid_groups: each ellipsoid's collision groups (collisionGroups of its ProxySource: bit
  // 1 << Chain per body chain it belongs to), for the collision groups below. cut_from_dressed:
  // the garment's rest shape becomes the shape it has once pushed outside the ellipsoids (without
  // gravity), as a tailor would let it out: for meshes made on another body (OBJ garments), which
  // sit tight on that body's skin and would otherwise be stretched by the ellipsoids' bulges and
  // the collision margin.
  // What a garment's torso cloth meets beyond the torso's and the head's ellipsoids (maskFor,
  // applyLegGroups): an OBJ garment nothing more; template trousers the leg on its side; the
  // other templates that and the pelvis fill (proxies/proxy_builder.h), which trousers, their seat
  // and crotch cut round it, do not meet: meeting it stretched their seat (docs/proxies.md).
  enum class TorsoReach : uint8_t { Torso, Legs, LegsAndPelvis };
  // A dressing in progress: what dress() needs to go on with a garment that create() made but, asked
  // to defer it, did not dress. It keeps its own copies of the rest body and its ellipsoids, so the
  // caller's may change meanwhile. Why: a garment cut again mid-session (the skeleton's
  // calibration) is dressed a few frames per step beside the one it replaces, instead of in one
  // step (Context::Recut in capi/context.h; docs/garments.md, "Cut by kind").
  struct Dressing {
    int frames = 0;       // simulated 1/30 s frames of the whole dressing
    int grow = 0;         // of which the body grows to full size
    int done_frames = 0;  // run so far
    bool finished = false;
    bool cut_from_dressed = false;
    ClothSolverKind solver = ClothSolverKind::Xpbd;
    GarmentSimParams params;
    TopologyParams topology;
    std::shared_ptr<const BodyModel> body_copy;  // deferred: the rest body, copied
    const BodyModel* body = nullptr;             // body_copy, or create()'s body_rest
    std::vector<Ellipsoid> rest, from, to;       // the rest ellipsoids; the frame's, grown
  };
  // deferred: when given, the garment comes back made and placed on the rest pose but not dressed,
  // and *deferred holds what dress() needs; else it is dressed before create() returns.
  static std::unique_ptr<GarmentSim> create(const GarmentMesh& mesh, const TopologyParams& topo,
                                            ClothSolverKind solver, const GarmentSimParams& params,
                                            float dress_time_s, const BodyModel& body_rest,
                                            const std::vector<Ellipsoid>& rest_ellipsoids,
                                            const std::vector<uint8_t>& ellipsoid_groups,
                                            std::string& err, bool cut_from_dressed = false,
                                            TorsoReach torso_reach = TorsoReach::Torso,
                                            Dressing* deferred = nullptr);
  // Runs up to `frames` more frames of a deferred dressing, and when none are left finishes it
  // (the dressed shape kept, the skin and openings bound): d.finished. Once finished, a call does
  // nothing and returns true. False + err when the garment did not settle (non-finite positions);
  // it is then unusable.
  bool dress(Dressing& d, int frames, std::string& err);
  // A template garment: makeGarmentTemplate on body_rest, then create(). It remembers the template
  // and its layout, so refitted() cuts it again as that template on the new body.
  static std::unique_ptr<GarmentSim> createTemplate(const GarmentTemplateParams& tmpl, const TopologyParams& topo,
                                                    ClothSolverKind solver, const GarmentSimParams& params,
                                                    float dress_time_s, const BodyModel& body_rest,
                                                    const std::vector<Ellipsoid>& rest_ellipsoids,
                                                    const std::vector<uint8_t>& ellipsoid_groups, std::string& err);
  ~GarmentSim();

  // Refitting to a new body shape (the host changed the person's height, weight or girths while
  // the garment is worn): a new garment like this one, its cut carried to the body `body_rest` (the
  // context's new rest body, same ring layout) by ring skinning, then dressed there as create()
  // dresses with cut_from_dressed: the skinning scales the garment's gap to the body with the
  // girths, so where the new body's ellipsoids bulge past it the cut is let out instead of
  // stretched (on a 1.2 m / BMI 16 body that took the P99 stretch from 0.44 to 0.27). The cut
  // carried is always the one create() got, bound to the rest body of that time, so refitting
  // back and forth does not drift. Same particles, triangles, attachments, solver
  // and parameters; it sits on the new rest pose until its first step places it on the tracked
  // body (as a new garment does). Null + err when the dressing fails. docs/garments.md, "Body
  // shape changes".
  // remake_template: a template garment is made again on body_rest with its first build's layout
  // (TemplateLayout) instead of being carried by skinning (the skeleton's calibration:
  // docs/garments.md, "Cut for the person's skeleton"; a shape change carries it, which measured
  // closer to a garment made for the new body there).
  // deferred: as create()'s (the new garment comes back undressed).
  std::unique_ptr<GarmentSim> refitted(const BodyModel& body_rest, const std::vector<Ellipsoid>& rest_ellipsoids,
                                       const std::vector<uint8_t>& ellipsoid_groups, std::string& err,
                                       bool remake_template = false, Dressing* deferred = nullptr) const;
  // Takes over `fresh` (from refitted()) and keeps what identifies this garment to its owner: the
  // C ABI token and owner, its step count and glitch counters; counts the refit.
  void replaceWith(GarmentSim&& fresh);
  uint32_t refits() const { return refits_; }

  bool setParams(const GarmentSimParams& params, std::string& err);
  const GarmentSimParams& params() const { return params_; }
  ClothSolverKind solver() const { return kind_; }

  // Advances dt seconds while the body moves from the state of the last step (`start`
  // ellipsoids, the rings seen then) to `body` / `end` now. `teleported`: the tracker saw a jump.
  // dt must be finite and > 0 (checked by the caller); ellipsoid counts must match creation's.
  void step(const BodyModel& body, const std::vector<Ellipsoid>& start,
            const std::vector<Ellipsoid>& end, float dt, bool teleported);
  // step() in two halves, so that a context can run many garments' device frames in one launch
  // (docs/opencl.md, "Batching"): stepBegin is the host part (inertia carry, pins, teleports and
  // pose jumps, the ellipsoid spans) and runs the frame, except that with allow_staging a device
  // solver may only stage it: the caller then runs every staged frame (runStagedClFrames) before
  // stepEnd, the NaN guard and bookkeeping. body and end must live until stepEnd.
  // step() = stepBegin without staging + stepEnd: the same results either way.
  void stepBegin(const BodyModel& body, const std::vector<Ellipsoid>& start,
                 const std::vector<Ellipsoid>& end, float dt, bool teleported, bool allow_staging);
  void stepEnd();
  bool frameStaged() const { return staged_; }

  size_t particleCount() const;
  const Eigen::Vector4f* positions() const;   // xyz metres, w = inverse mass (0 = pinned)
  const Eigen::Vector4f* velocities() const;
  const std::vector<uint32_t>& indices() const { return mesh_.indices; }
  const GarmentTopology& topology() const { return topology_; }
  const GarmentMesh& mesh() const { return mesh_; }
  // Area-weighted unit vertex normals of the current positions (on the OpenCL backend the
  // device's, computed with the frame once the host reads normals: docs/opencl.md), into a buffer
  // the garment owns (valid until the next call; no allocation after the first).
  const std::vector<Vec3>& normals() const;
  // Collision groups: each particle belongs to the body chain nearest to it on the rest body and
  // collides only with the ellipsoids of the chains in its mask (bit c = Chain c): torso cloth
  // with torso and head, a sleeve with its arm, a trouser leg with its leg and the torso. Where
  // two body parts touch (an arm hanging against the torso) their ellipsoids overlap and cloth
  // between them has no place outside both; with groups, sleeve and torso cloth each stay on
  // their own part instead of being squeezed out through one of them.
  const std::vector<uint8_t>& particleMasks() const { return masks_; }
  // Each ellipsoid's collision groups now (the ones given to create, plus kTorsoOverLegL / R on
  // the leg ellipsoids torso cloth meets this step; the pelvis fill's 0 while nothing meets it).
  const std::vector<uint8_t>& ellipsoidGroups() const { return groups_; }
  static uint8_t maskForChain(int chain);
  // Torso cloth of a template garment (create's torso_reach) also collides with the leg on
  // its side, through the group bits kTorsoOverLegL / R (proxies/proxy_builder.h), which a leg's
  // ellipsoids carry only while that leg is trusted (setLegsTrusted) and clear of torso cloth
  // (updateLegClearance). Why: a shirt's hem hangs over the tops of the thighs, and when the hip
  // bent (the CMU hop takes) the thighs rose through it, the deepest body penetration of the
  // shared takes (docs/garments.md, "Torso cloth over the thighs"). Why not always: a leg the
  // sensor only infers is a guess; and an OBJ garment's torso cloth may be a suit's seat, which on
  // a heavy body tore between the hip and thigh ellipsoids.
  // rings: body's rings, or a copy of them with the arms moved clear of the torso (create()).
  // sleeve_meets_torso: the cloth nearest an upper arm, from kSleeveMeetsTorsoFrom to
  // kSleeveMeetsTorsoTo of the way from the shoulder joint to the elbow, also collides with the
  // torso. create() sets it when the tracked bodies keep their arms clear of the torso
  // (BodyModelParams::tracked_arms_clear_torso) by more than twice the garment's collision margin
  // at creation, which leaves room for it between the two. Why:
  // a hanging sleeve's inner side, meeting only the arm, fell into the torso beside it (Ges01's
  // worst frame: 12.9 mm P99, sleeve vertices up to 31 mm deep; docs/garments.md, "Sleeves meet
  // the torso"). Not the armpit end (the arm's junction ellipsoids overlap the torso's, cloth
  // there would be caught between them) nor the elbow end and the forearm (no clearance there:
  // the elbows hang against the hips, forearms cross the belly).
  static uint8_t maskFor(const BodyModel& body, const std::vector<RingPose>& rings, const Vec3& p,
                         bool torso_meets_legs, bool sleeve_meets_torso);
  static constexpr float kSleeveMeetsTorsoFrom = 0.3f, kSleeveMeetsTorsoTo = 0.8f;
  // Whether each leg's ellipsoids are trusted this frame (Context: hip and knee Tracked); while
  // one is not, torso cloth passes through it as before. Cheap when nothing changed.
  void setLegsTrusted(bool left, bool right);
  // The tracker saw a pose jump since the last step (SkeletonTracker::poseJumpedLastPush: the
  // torso, or a tracked limb bone, turned farther than a person can): the next step treats it as
  // one as it does a pelvis turning too fast (poseJumped()): the state before it kept, the garment
  // placed on the new pose, and put back when a jump returns to a pose its pins match. Why: a
  // thigh reported pointing up for a second dragged trouser legs through the torso, and they did
  // not come back (docs/robustness.md, "The same scenarios on the other garments").
  void setPoseJumped(bool jumped) { host_pose_jump_ = jumped; }
  // The body chain whose surface p is nearest (rings: as maskFor's). u, when given: where along
  // that chain, in its joints' units (an arm: 0 at the shoulder joint, 1 at the elbow).
  static int nearestChain(const BodyModel& body, const std::vector<RingPose>& rings, const Vec3& p,
                          float* u = nullptr);

  // Proxy culling (capi/adaptive.h): the indices (increasing) of the ellipsoids the garment can
  // reach now; step() hands the collider only those, with their groups. The others are ones no
  // particle of this garment can touch, so the result is the same as with all of them. Empty: all.
  void setReachable(const std::vector<int>& indices);
  const std::vector<int>& reachable() const { return reach_; }
  // Where placeOnBody (the first tracked frame, a pose jump with nothing to restore) takes the
  // garment from its rest pose into the pose (cloth/placement_path.h); null: skinned straight
  // onto it. Not owned; the context sets it before each stepBegin.
  void setPlacementPath(PlacementPath* path) { path_ = path; }
  // The context skipped this garment's step (it is asleep): the last step's statistics say that
  // nothing ran.
  void markSkipped() { last_ = GarmentStepStats{}; }

  const GarmentStepStats& lastStep() const { return last_; }
  // Pose jumps that came back and found the garment's state from before the jump (restored).
  uint32_t poseJumpRestores() const { return jump_restores_; }
  // Noise bursts that ended with the garment restored to its state before the burst.
  uint32_t noiseBurstRestores() const { return burst_restores_; }
  // The tracker's sensor-noise estimate (SkeletonTracker::noiseSigmaM), given before each step.
  void setTrackingNoise(float sigma_m) { tracking_noise_m_ = sigma_m >= 0.0f ? sigma_m : 0.0f; }
  uint64_t steps() const { return steps_; }

  // Accuracy now against `ellipsoids` and, when `body_bvh` is non-null, the body mesh it holds;
  // with `body` (the body now, same ring layout as at dressing), whether the openings still go
  // round the body parts they went round when dressed.
  GarmentAccuracy measure(const std::vector<Ellipsoid>& ellipsoids, const TriangleBvh* body_bvh,
                          const BodyModel* body = nullptr) const;

  struct Solver;  // the solver behind the garment (cloth/garment_solver.h)
  Solver* solverFace() { return solver_.get(); }

  // Backends (docs/opencl.md). A factory builds a solver from the garment's topology, its state
  // now (particleCount() positions and velocities, xyzw) and its collision masks.
  using SolverFactory = std::function<std::unique_ptr<Solver>(
      const GarmentTopology&, const Eigen::Vector4f* x, const Eigen::Vector4f* v,
      const std::vector<uint8_t>& masks, std::string& err)>;
  // Replaces the XPBD solver by make(...)'s with the current params; false + err and nothing
  // changed when make or setParams fails, or for the mass-spring solver (CPU only).
  bool replaceSolver(const SolverFactory& make, std::string& err);
  // Back to the CPU XPBD solver with the current positions and velocities.
  bool useCpuSolver(std::string& err);
  GarmentBackend backend() const;
  // Whether the solver's device failed (its last frame was not applied); the reason in *err.
  bool deviceFailed(std::string* err) const;

  // Bookkeeping of the C ABI layer (its handle token and owning context); unused here.
  void* api_token = nullptr;
  void* api_owner = nullptr;

 private:
  GarmentSim() = default;
  void pinTargets(const BodyModel& body, std::vector<Vec3>& out) const;
  void runFrame(const std::vector<Ellipsoid>& start, const std::vector<Ellipsoid>& end,
                const std::vector<Vec3>& pins, float dt);
  // runFrame for the step's own frame: staged when stepBegin allows it (never while dressing
  // or settling in placeOnBody).
  void runStepFrame(const std::vector<Ellipsoid>& start, const std::vector<Ellipsoid>& end,
                    const std::vector<Vec3>& pins, float dt);
  void addFrameStats(int substeps);  // a frame's substeps and collision counters into last_
  bool allow_staging_ = false, staging_ = false, staged_ = false;
  int staged_substeps_ = 0;
  const BodyModel* pending_body_ = nullptr;  // stepBegin's arguments, for stepEnd
  const std::vector<Ellipsoid>* pending_end_ = nullptr;
  std::chrono::steady_clock::time_point pending_t0_{};
  double begin_ms_ = 0.0;  // the last stepBegin's own time (GarmentStepStats::total_ms)
  // The pelvis turned farther since the last step than a person can turn in dt.
  bool poseJumped(const RingPose& pelvis, float dt) const;
  void carry(const Mat3& R, const Vec3& pivot, const Vec3& t, float velocity_scale);
  // Places the dressed garment on `body` and settles it for blend_in_s: skinned onto the first
  // pose of the placement path (setPlacementPath) and carried through its poses into `body`, or,
  // without one (or on a pose near the rest pose), skinned straight onto `body`.
  void placeOnBody(const BodyModel& body, const std::vector<Ellipsoid>& ellipsoids);
  // Recovery from tracking glitches (garment_recovery.cpp, docs/robustness.md). A skeleton that
  // flips (or is swapped with another person's) for a moment, or a burst of sensor noise, leaves
  // the garment tangled or stretched well after the glitch ends: friction lets cloth caught on the
  // wrong side of a limb slide back only slowly. So the garment's state from before the glitch is
  // kept relative to the pelvis ring (with its attachment targets, its ellipsoids and where the
  // shoulders sat), and when the glitch ends with the attachments back within kRestoreMatchM of
  // where they were, that state is restored and swept to the current pose by kCatchUpFrames frames
  // of simulation.
  struct KeptState {
    std::vector<Vec3> x, pins;          // positions and attachment targets, pelvis ring frame
    std::vector<Ellipsoid> ellipsoids;  // the garment's ellipsoids then, pelvis ring frame
    ShoulderSeams shoulders;            // where the shoulders sat then (a placement restarts it)
    double time_s = 0.0;                // sim_time_s_ when kept
    bool valid = false;
  };
  void keepState(KeptState& k, const std::vector<Ellipsoid>& ellipsoids, const RingPose& pelvis,
                 const std::vector<Vec3>& pins) const;
  bool restoreState(KeptState& k, const BodyModel& body, const RingPose& pelvis,
                    const std::vector<Ellipsoid>& end);
  // At a pose jump: keeps the state the garment had on the last pose (unless a younger kept
  // state from an earlier jump of the same glitch exists, A -> B -> C -> A).
  void keepBeforeJump(const std::vector<Ellipsoid>& start);
  // Follows the tracker's noise estimate; true on the step a noise burst ends.
  bool noiseBurstEnded();
  void keepCalmState(const RingPose& pelvis);  // stepEnd: a snapshot every kCalmEveryS while calm
  KeptState before_jump_, before_burst_;
  KeptState calm_[3];
  int calm_next_ = 0;
  double calm_last_s_ = -1e9;
  bool in_burst_ = false;
  float tracking_noise_m_ = 0.0f;
  double sim_time_s_ = 0.0;  // the dt of every step so far
  uint32_t jump_restores_ = 0, burst_restores_ = 0;
  std::vector<Ellipsoid> catch_kept_, catch_a_, catch_b_;  // restoreState scratch
  std::vector<Vec3> catch_kept_pins_, catch_pins_;

  // What refitted() carries to another body: the mesh and choices create() got, and the rings
  // of the rest body of the time (the mesh is bound to them when a refit needs it, not at every
  // creation: binding costs ~100 ms at 32 000 particles). Shared by a garment and its refits.
  struct Origin {
    GarmentMesh mesh;
    TopologyParams topology;
    float dress_time_s = 0.0f;
    std::vector<RingPose> rest_rings;
    // A template garment (createTemplate): cut again as that template, with the same layout.
    bool from_template = false;
    GarmentTemplateParams tmpl;
    TemplateLayout layout;
  };
  std::shared_ptr<const Origin> origin_;
  GarmentSim& operator=(GarmentSim&&) noexcept;  // replaceWith

  GarmentMesh mesh_;
  GarmentTopology topology_;
  ClothSolverKind kind_ = ClothSolverKind::Xpbd;
  GarmentSimParams params_;
  std::unique_ptr<Solver> solver_;
  EllipsoidCollider collider_;
  std::vector<uint8_t> masks_, groups_;  // groups_: base_groups_ as met now (applyLegGroups)
  std::vector<uint8_t> rim_gate_;        // runStepFrame: the particles of openings on their part
  std::vector<uint8_t> base_groups_;      // each ellipsoid's collision groups, as given to create()
  // Torso cloth meets a leg's ellipsoid while the host trusts that leg (setLegsTrusted) and the
  // ellipsoid is clear: it held no torso cloth when the garment was last placed on the body (first
  // frame, pose jump) or when the leg was last trusted again, or none since (leg_clear_, one entry
  // per ellipsoid; empty: all clear). Pushed out at once, cloth a leg had passed into tore.
  TorsoReach torso_reach_ = TorsoReach::Torso;  // create's: not Torso = torso cloth has kTorsoOverLeg bits
  bool host_pose_jump_ = false;  // setPoseJumped
  bool host_legs_[2] = {true, true};
  uint8_t recheck_legs_ = 0;  // bit per side: trusted again since the last step
  std::vector<uint8_t> leg_clear_;
  size_t unclear_legs_ = 0;
  void applyLegGroups();
  bool torsoClothInside(const Ellipsoid& e, uint8_t over) const;
  // The reachable `ellipsoids` (this step's): an unclear leg ellipsoid becomes clear once it holds
  // no torso cloth; those of the sides in recheck_sides (bit 0 left, 1 right) are decided anew.
  void updateLegClearance(const std::vector<Ellipsoid>& ellipsoids, uint8_t recheck_sides);

  // The pelvis ring pose the garment saw at the end of its last step (inertia scaling, teleports).
  int pelvis_ring_ = 0;
  Vec3 seen_pelvis_c_ = Vec3::Zero();
  Mat3 seen_pelvis_f_ = Mat3::Identity();
  std::vector<Vec3> seen_pins_;  // attachment targets on the rest body (dressing)
  bool tracked_ = false;  // false until the first step (the garment still sits on the rest pose)
  PlacementPath* path_ = nullptr;  // setPlacementPath
  std::vector<Ellipsoid> path_from_, path_to_;  // placeOnBody's scratch: a path pose's reachable ones

  // The dressed shape on the rest pose, bound to the rest body's rings.
  std::vector<Vec3> dressed_;
  RingSkin skin_;
  GarmentOpenings openings_;  // bound with skin_, to the dressed garment on the rest body
  ShoulderSeams shoulders_;   // seam pins that follow the shoulders (cloth/shoulder_seams.h)

  // Per-step scratch (sized once).
  std::vector<Vec3> pins_, scratch3_;
  std::vector<Ellipsoid> carried_start_;
  mutable std::vector<Vec3> normal_positions_, normals_;  // normals() scratch
  // setReachable(): the reachable indices, their groups, and the step's ellipsoids picked from
  // the full lists.
  std::vector<int> reach_;
  std::vector<uint8_t> reach_groups_;
  std::vector<Ellipsoid> reach_start_, reach_end_;
  const std::vector<Ellipsoid>& pickReachable(const std::vector<Ellipsoid>& all, std::vector<Ellipsoid>& out) const;
  GarmentStepStats last_;
  uint64_t steps_ = 0;
  uint32_t refits_ = 0;
};

}  // namespace drape
