// Fuzz target: the C ABI call sequence. The input is a little program: each byte chooses an
// operation and the bytes after it its arguments. Up to three contexts and six garments live at
// once; handles destroyed earlier stay in play (they must be refused, never dereferenced).
// Joints, body shapes, cloth parameters, dt and buffer capacities come from the bytes, with NaN,
// Inf, 1e30 and out-of-range values among them. Any result code is fine; a crash, a sanitizer
// report, DRAPE_ERROR_INTERNAL, or a non-finite number read back after DRAPE_OK is a bug.
// Garments are small templates (200-400 particles) or tiny meshes so an execution stays fast.
#include "fuzz_support.h"

#include <algorithm>
#include <vector>

using namespace drape_fuzz;

namespace {

constexpr int kContexts = 3;
constexpr int kGarments = 6;
constexpr int kMaxOps = 96;
constexpr int kMaxSteps = 16;  // cloth steps per input (each up to ~10 substeps of 400 particles)
// Fidelity measurements per input: ~1 ms each on the default body, but 0.35 s under ASan on a body of
// 32 points per ring with 3 extra rings per segment, and an input that asked for one in each of
// its 36 reads took 13 s, past libFuzzer's 10 s timeout (tests/fuzz/regressions/capi).
constexpr int kMaxFidelity = 4;

// The same person in another layout: Kinect v1 (20) or Azure (32, extra points placed by hand).
std::vector<drape_joint> poseFor(int32_t layout, double t) {
  drape_joint k[25];
  drape_fuzz::standingPose25(t, 0.08f, k);
  if (layout == DRAPE_LAYOUT_KINECT1) {
    std::vector<drape_joint> v(20);
    v[0] = k[0];
    v[1] = k[1];
    v[2] = k[20];
    v[3] = k[3];
    for (int i = 4; i < 20; ++i) v[i] = k[i];
    return v;
  }
  if (layout == DRAPE_LAYOUT_AZURE) {
    std::vector<drape_joint> a(32);
    const int from[18] = {0, 1, 20, 2, 20, 4, 5, 6, 7, 21, 22, 20, 8, 9, 10, 11, 23, 24};
    for (int i = 0; i < 18; ++i) a[i] = k[from[i]];
    a[2].position.y -= 0.1f;  // chest between navel and spine-shoulder
    a[4].position.x -= 0.05f;
    a[11].position.x += 0.05f;
    for (int i = 0; i < 8; ++i) a[18 + i] = k[12 + i];
    for (int i = 26; i < 32; ++i) a[i] = k[3];
    a[27].position.z -= 0.09f;
    a[28].position.x -= 0.03f;
    a[29].position.x -= 0.07f;
    a[30].position.x += 0.03f;
    a[31].position.x += 0.07f;
    return a;
  }
  return std::vector<drape_joint>(k, k + 25);
}

uint32_t jointCount(int32_t layout) {
  return layout == DRAPE_LAYOUT_KINECT1 ? 20u : layout == DRAPE_LAYOUT_AZURE ? 32u : 25u;
}

struct Ctx {
  drape_context* handle = nullptr;
  double t = 0.0;
  bool updated = false;  // an update (or step) succeeded, so reads after OK must be finite
};
struct Gar {
  drape_garment* handle = nullptr;
  int ctx = -1;
};

struct Machine {
  Bytes in;
  Ctx ctx[kContexts];
  Gar gar[kGarments];
  std::vector<drape_context*> dead_contexts;
  std::vector<drape_garment*> dead_garments;
  int steps = 0;
  int fidelity = 0;

  explicit Machine(Bytes b) : in(b) {}

  drape_context* pickContext() {
    const uint8_t k = in.u8();
    if (k < 240) return ctx[k % kContexts].handle;  // may be NULL: a NULL handle is a valid test
    if (!dead_contexts.empty()) return dead_contexts[k % dead_contexts.size()];
    return reinterpret_cast<drape_context*>(static_cast<uintptr_t>(0x1000 + k));  // never created
  }
  int contextSlot() { return in.u8() % kContexts; }
  drape_garment* pickGarment() {
    const uint8_t k = in.u8();
    if (k < 240) return gar[k % kGarments].handle;
    if (!dead_garments.empty()) return dead_garments[k % dead_garments.size()];
    return reinterpret_cast<drape_garment*>(static_cast<uintptr_t>(0x2000 + k));
  }
  int freeGarmentSlot() {
    for (int i = 0; i < kGarments; ++i)
      if (!gar[i].handle) return i;
    return -1;
  }
  Ctx* slotOf(drape_context* h) {
    if (!h) return nullptr;
    for (Ctx& c : ctx)
      if (c.handle == h) return &c;
    return nullptr;
  }

  // --------------------------------------------------------------------------------------------
  void createContext() {
    const int s = contextSlot();
    if (ctx[s].handle) return;
    drape_context_desc d;
    drape_context_desc_init(&d);
    const uint8_t mode = in.u8();
    if (mode & 1) {
      static const uint32_t kRing[] = {8, 12, 16, 20, 24, 32, 7, 0};
      d.ring_points = kRing[in.u8() % 8];
      d.rings_per_segment = in.u8() % 4;
      d.calibration_frames = in.u8() % 64;  // 0 is out of range
      d.filter = static_cast<int32_t>(in.u8() % 4);  // 3 is out of range
      d.proxy_rule = static_cast<int32_t>(in.u8() % 3);
      d.teleport_distance_m = in.inRange(0.01f, 5.0f);
    }
    if (mode & 2) {
      d.filter_min_cutoff_hz = in.inRange(0.001f, 100.0f);
      d.filter_beta = in.inRange(0.0f, 100.0f);
      d.smoothing = in.inRange(0.0f, 0.999f);
      d.prediction = in.inRange(0.0f, 10.0f);
      d.jitter_radius_m = in.inRange(0.0f, 1.0f);
    }
    if (mode & 4) d.struct_size = in.u8();  // usually too small
    if (mode & 8) d.garment_fit = static_cast<int32_t>(in.u8() % 3);  // 2 is out of range
    if (mode & 64) {
      d.arms_clear_torso = static_cast<int32_t>(in.u8() % 3);  // 2 is out of range
      d.arm_torso_clearance_m = in.inRange(-0.01f, 0.06f);     // [0, 0.05] in range
    }
    if (mode & 128) {
      // The sized init over the desc drawn so far: sizes round the first layout's 64 and this
      // header's 72 (outside [64, 72]: refused, nothing written; inside: the fields the size
      // covers back to their defaults, struct_size that size).
      const uint32_t size = 60 + in.u8() % 16u;
      const drape_context_desc before = d;
      const drape_result r = DRAPE_FUZZ_CALL(drape_context_desc_init_sized(&d, size));
      const bool in_range = size >= DRAPE_CONTEXT_DESC_SIZE_V1 && size <= sizeof(d);
      DRAPE_FUZZ_CHECK((r == DRAPE_OK) == in_range, "the sized init takes exactly the sizes it documents");
      DRAPE_FUZZ_CHECK(std::memcmp(reinterpret_cast<const unsigned char*>(&d) + (in_range ? size : 0),
                                   reinterpret_cast<const unsigned char*>(&before) + (in_range ? size : 0),
                                   sizeof(d) - (in_range ? size : 0)) == 0,
                       "the sized init writes nothing past the size it is given");
    }
    drape_context* h = nullptr;
    if (DRAPE_FUZZ_CALL(drape_context_create((mode & 16) && (mode & 32) ? nullptr : &d, &h)) == DRAPE_OK) {
      DRAPE_FUZZ_CHECK(h != nullptr, "create OK gives a handle");
      ctx[s] = Ctx{h, 0.0, false};
    }
  }

  void destroyContext() {
    const int s = contextSlot();
    if (!ctx[s].handle) return;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_destroy(ctx[s].handle)) == DRAPE_OK, "destroying a live context");
    dead_contexts.push_back(ctx[s].handle);
    for (Gar& g : gar) {
      if (g.ctx == s && g.handle) {
        dead_garments.push_back(g.handle);
        g = Gar{};
      }
    }
    ctx[s] = Ctx{};
  }

  void push(bool raw) {
    drape_context* h = pickContext();
    Ctx* c = slotOf(h);
    const uint8_t lay = in.u8();
    int32_t layout = 1 + lay % 3;
    if (lay >= 250) layout = static_cast<int32_t>(lay) - 252;  // 0 (AUTO), -2, 3 ...
    // Timestamp step: normally 1/30 s, sometimes 1/240..1/10, repeated, backwards or huge.
    double dt = 1.0 / 30.0;
    const uint8_t tk = in.u8();
    if (tk < 64) dt = 1.0 / 240.0 + (0.1 - 1.0 / 240.0) * tk / 63.0;
    else if (tk == 64) dt = 0.0;
    else if (tk == 65) dt = -0.01;
    else if (tk == 66) dt = 1e6;
    else if (tk == 67) dt = static_cast<double>(in.nasty());
    const double base = c ? c->t : 0.0;
    const double t = base + dt;
    std::vector<drape_joint> j;
    const uint32_t count = jointCount(layout);
    if (raw) {
      j.resize(count);
      for (drape_joint& q : j) {
        q.position = drape_vec3{in.rawFloat(), in.rawFloat(), in.rawFloat()};
        q.tracking_state = static_cast<int32_t>(in.u8() % 4);  // 3 is out of range
      }
    } else {
      j = poseFor(layout >= 1 && layout <= 3 ? layout : DRAPE_LAYOUT_KINECT2, t);
      j.resize(count);
      // Perturbations: a joint (or all) gets a nasty value, teleports, jitters, loses tracking.
      const uint8_t n = in.u8() % 4;
      for (uint8_t k = 0; k < n; ++k) {
        const uint8_t what = in.u8();
        const uint32_t ji = in.u8() % count;
        switch (what % 6) {
          case 0: j[ji].position.x = in.nasty(); break;
          case 1: j[ji].position.y = in.nasty(); break;
          case 2: {  // teleport: the whole person moves up to 2 m
            const float d = in.inRange(-2.0f, 2.0f);
            for (drape_joint& q : j) q.position.z += d;
            break;
          }
          case 3: j[ji].tracking_state = static_cast<int32_t>(in.u8() % 4); break;
          case 4: in.u8(), j[ji].position = j[(ji + 1) % count].position; break;  // zero-length bone
          case 5: {  // jitter: up to 5 cm per joint from a seed byte
            uint32_t seed = in.u8() * 2654435761u + 1u;
            for (drape_joint& q : j) {
              seed = seed * 1664525u + 1013904223u;
              q.position.x += 0.05f * (static_cast<float>(seed >> 8) / 16777216.0f - 0.5f);
              seed = seed * 1664525u + 1013904223u;
              q.position.y += 0.05f * (static_cast<float>(seed >> 8) / 16777216.0f - 0.5f);
            }
            break;
          }
        }
      }
    }
    drape_skeleton_frame f;
    std::memset(&f, 0, sizeof f);
    f.struct_size = sizeof f;
    f.layout = layout;
    f.joint_count = static_cast<uint32_t>(j.size());
    f.timestamp_s = t;
    f.joints = j.data();
    std::vector<drape_quat> q;
    const uint8_t extra = in.u8();
    if (extra == 1) f.joint_count = in.u8();
    if (extra == 2) f.reserved = 1;
    if (extra == 3) f.struct_size = in.u8();
    if (extra == 4) {
      q.resize(j.size());
      for (drape_quat& o : q) o = drape_quat{0, 0, 0, 1};
      q[in.u8() % q.size()].w = in.nasty();
      f.orientations = q.data();
    }
    if (f.joint_count > j.size()) f.joint_count = static_cast<uint32_t>(j.size());  // never overread our buffer
    if (extra == 5) f.joints = nullptr;
    if (DRAPE_FUZZ_CALL(drape_context_push_skeleton(h, extra == 6 ? nullptr : &f)) == DRAPE_OK && c) c->t = t;
  }

  void update() {
    drape_context* h = pickContext();
    if (DRAPE_FUZZ_CALL(drape_context_update(h)) == DRAPE_OK)
      if (Ctx* c = slotOf(h)) c->updated = true;
  }

  void step() {
    drape_context* h = pickContext();
    static const float kDt[] = {1.0f / 30.0f, 1.0f / 240.0f, 1.0f / 10.0f, 1.0f / 60.0f, 0.0f, -1.0f, 10.0f, 10.5f};
    const uint8_t k = in.u8();
    float dt = k < 8 ? kDt[k] : k < 250 ? 1.0f / 240.0f + (0.1f - 1.0f / 240.0f) * (k - 8) / 241.0f : in.nasty();
    if (steps >= kMaxSteps) return;
    ++steps;
    if (DRAPE_FUZZ_CALL(drape_context_step(h, dt)) == DRAPE_OK) {
      if (Ctx* c = slotOf(h)) c->updated = true;
      for (Gar& g : gar)
        if (g.handle && ctx[g.ctx].handle == h) checkGarment(g.handle);
    }
  }

  void setShape() {
    drape_context* h = pickContext();
    drape_body_shape s;
    drape_body_shape_init(&s);
    const uint8_t mode = in.u8();
    // BMI 15..45 at heights 1.0..2.2 m, or anything.
    const float height = in.inRange(1.0f, 2.2f);
    const float bmi = in.inRange(15.0f, 45.0f);
    s.height_m = height;
    s.weight_kg = bmi * height * height;
    s.sex = static_cast<int32_t>(in.u8() % 4);
    if (mode & 1) s.waist_mm = in.inRange(0.0f, 3000.0f);
    if (mode & 2) s.chest_mm = in.inRange(0.0f, 3000.0f);
    if (mode & 4) s.upper_arm_mm = in.inRange(0.0f, 3000.0f);
    if (mode & 8) s.thigh_mm = in.inRange(0.0f, 3000.0f);
    if (mode & 16) s.weight_kg = in.nasty();
    if (mode & 32) s.struct_size = in.u8();
    if (DRAPE_FUZZ_CALL(drape_context_set_body_shape(h, &s)) == DRAPE_OK) {
      drape_body_shape back;
      drape_body_shape_init(&back);
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_get_body_shape(h, &back)) == DRAPE_OK, "get shape after set");
      DRAPE_FUZZ_CHECK(back.height_m == s.height_m && back.weight_kg == s.weight_kg, "shape comes back as given");
      DRAPE_FUZZ_CHECK(std::isfinite(back.neck_mm) && std::isfinite(back.chest_mm) && std::isfinite(back.waist_mm) &&
                           std::isfinite(back.hip_mm) && std::isfinite(back.thigh_mm) && std::isfinite(back.calf_mm) &&
                           std::isfinite(back.upper_arm_mm) && std::isfinite(back.forearm_mm),
                       "resolved girths finite");
    }
  }

  void clothParams(drape_cloth_params& c) {
    drape_cloth_params_init(&c);
    const uint8_t mode = in.u8();
    if (mode & 1) {
      c.substep_hz = in.inRange(30.0f, 1200.0f);
      c.max_substeps = 1 + in.u8() % 40;
      c.max_step_s = in.inRange(1e-4f, 1.0f);
    }
    if (mode & 2) {
      c.stretch_compliance = in.inRange(0.0f, 1.0f);
      c.shear_compliance = in.inRange(0.0f, 1.0f);
      c.bend_compliance = in.inRange(0.0f, 1.0f);
      c.tether_compliance = in.inRange(0.0f, 1.0f);
      c.tether_scale = in.inRange(1.0f, 10.0f);
    }
    if (mode & 4) {
      c.gravity = drape_vec3{in.inRange(-1000.0f, 1000.0f), in.inRange(-1000.0f, 1000.0f), 0.0f};
      c.wind = drape_vec3{in.inRange(-1000.0f, 1000.0f), 0.0f, in.inRange(-1000.0f, 1000.0f)};
      c.drag = in.inRange(0.0f, 1000.0f);
      c.damping = in.inRange(0.0f, 1000.0f);
      c.max_speed = in.inRange(0.0f, 1000.0f);
    }
    if (mode & 8) {
      c.static_friction = in.inRange(0.0f, 10.0f);
      c.kinetic_friction = in.inRange(0.0f, 10.0f);
      c.collision_margin_m = in.inRange(0.0f, 0.05f);
      c.contact_response = static_cast<int32_t>(in.u8() % 3);
      c.continuous_collision = in.u8() % 3;
    }
    if (mode & 16) {
      c.linear_inertia = in.inRange(0.0f, 1.0f);
      c.angular_inertia = in.inRange(0.0f, 1.0f);
      c.blend_in_s = in.inRange(0.0f, 2.0f);
      c.spring_stretch = in.inRange(0.0f, 1e6f);
      c.spring_shear = in.inRange(0.0f, 1e6f);
      c.spring_bend = in.inRange(0.0f, 1e6f);
      c.spring_damping = in.inRange(0.0f, 1e6f);
    }
    if (mode & 32) {
      c.strain_limit = in.inRange(-1.0f, 12.0f);  // outside [0, 10] is refused
      c.strain_limit_passes = in.u8() % 18;       // 0 and 17 are refused
    }
    // 128 .. 131: the first layout, collision_stride not read; 132 .. 135: the second,
    // strain_limit_passes not read
    if (mode & 64) c.struct_size = in.u8();
    if (mode & 128) c.collision_stride = in.u8() % 10;  // 9 is refused
  }

  void garmentDesc(drape_garment_desc& d) {
    drape_garment_desc_init(&d);
    d.dress_time_s = in.inRange(0.0f, 0.2f);
    const uint8_t mode = in.u8();
    if (mode & 1) d.solver = static_cast<int32_t>(in.u8() % 3);
    if (mode & 2) d.area_density = in.inRange(0.0f, 10.0f);
    if (mode & 4) d.max_tethers = in.u8() % 10;
    if (mode & 8) d.cut = static_cast<int32_t>(in.u8() % 5);  // 4 is out of range
  }

  void addTemplate() {
    drape_context* h = pickContext();
    const int s = freeGarmentSlot();
    drape_garment_template t;
    drape_garment_template_init(&t);
    t.kind = static_cast<int32_t>(in.u8() % 6);  // 5 is out of range
    t.particles = 200 + in.u8() % 201;
    if (in.u8() & 1) {
      t.ease_m = in.inRange(0.002f, 0.1f);
      t.length_scale = in.inRange(0.5f, 1.5f);
    }
    drape_garment_desc d;
    garmentDesc(d);
    drape_cloth_params c;
    clothParams(c);
    if (s < 0) return;
    drape_garment* g = nullptr;
    if (DRAPE_FUZZ_CALL(drape_context_add_garment_template(h, &d, &t, &c, &g)) == DRAPE_OK) {
      Ctx* owner = slotOf(h);
      DRAPE_FUZZ_CHECK(owner != nullptr && g != nullptr, "garment added to a live context");
      gar[s] = Gar{g, static_cast<int>(owner - ctx)};
      checkGarment(g);
    }
  }

  // A small mesh from the bytes: 3..24 vertices, 1..24 triangles, some indices out of range.
  void addMesh() {
    drape_context* h = pickContext();
    const int s = freeGarmentSlot();
    const uint32_t nv = 3 + in.u8() % 22;
    const uint32_t nt = 1 + in.u8() % 24;
    std::vector<drape_vec3> p(nv);
    for (uint32_t i = 0; i < nv; ++i) {
      // A strip around the chest in MakeHuman units (decimetres, facing +Z), perturbed.
      const float a = 6.2831853f * static_cast<float>(i) / static_cast<float>(nv);
      p[i] = drape_vec3{1.5f * std::cos(a) + in.inRange(-0.5f, 0.5f), 4.0f + (i % 2) * 1.0f + in.inRange(-0.5f, 0.5f),
                        1.2f * std::sin(a)};
    }
    std::vector<uint32_t> idx(3 * nt);
    for (uint32_t& k : idx) {
      const uint8_t b = in.u8();
      k = b < 250 ? b % nv : nv + (b - 250);
    }
    drape_mesh_fit fit;
    drape_mesh_fit_init(&fit);
    const uint8_t mode = in.u8();
    if (mode & 1) fit.unit_scale = in.inRange(0.0f, 1000.0f);
    if (mode & 2) fit.facing = static_cast<int32_t>(in.u8() % 3);
    if (mode & 4) {
      fit.source_height_m = in.inRange(0.8f, 2.5f);
      fit.source_weight_kg = in.inRange(15.0f, 300.0f);
      fit.source_arm_down_deg = in.inRange(0.0f, 90.0f);
      fit.source_elbow_flex_deg = in.inRange(0.0f, 150.0f);
      fit.source_leg_spread_deg = in.inRange(0.0f, 45.0f);
      fit.blend_m = in.inRange(0.0f, 0.2f);
    }
    if (mode & 8) fit.source_floor_y_m = in.inRange(-100.0f, 100.0f);
    drape_garment_desc d;
    garmentDesc(d);
    drape_cloth_params c;
    clothParams(c);
    if (s < 0) return;
    drape_garment* g = nullptr;
    if (DRAPE_FUZZ_CALL(drape_context_add_garment_mesh(h, p.data(), nv, idx.data(), 3 * nt, &fit, &d, &c, &g)) ==
        DRAPE_OK) {
      Ctx* owner = slotOf(h);
      DRAPE_FUZZ_CHECK(owner != nullptr && g != nullptr, "garment added to a live context");
      gar[s] = Gar{g, static_cast<int>(owner - ctx)};
      checkGarment(g);
    }
  }

  void setParams() {
    drape_garment* g = pickGarment();
    // Now and then a layer as well (drape_garment_set_layer): in range it comes back, outside it
    // is refused and changes nothing.
    const uint8_t lm = in.u8();
    if (lm & 1) {
      const int32_t layer = 3 * static_cast<int32_t>(static_cast<int8_t>(in.u8()));  // -384 .. 381
      int32_t before = -1000, after = -1000;
      const bool live = DRAPE_FUZZ_CALL(drape_garment_get_layer(g, &before)) == DRAPE_OK;
      const drape_result r = DRAPE_FUZZ_CALL(drape_garment_set_layer(g, layer));
      if (live) {
        DRAPE_FUZZ_CHECK(r == (layer >= 0 && layer <= 255 ? DRAPE_OK : DRAPE_ERROR_OUT_OF_RANGE), "set_layer's range");
        DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_get_layer(g, &after)) == DRAPE_OK, "get_layer after set");
        DRAPE_FUZZ_CHECK(after == (r == DRAPE_OK ? layer : before), "a layer comes back as set; a refused one changes nothing");
      } else {
        DRAPE_FUZZ_CHECK(r != DRAPE_OK, "set_layer on a dead garment");
      }
    }
    drape_cloth_params c;
    clothParams(c);
    drape_cloth_params before;
    drape_cloth_params_init(&before);
    const bool live = DRAPE_FUZZ_CALL(drape_garment_get_params(g, &before)) == DRAPE_OK;
    if (DRAPE_FUZZ_CALL(drape_garment_set_params(g, &c)) == DRAPE_OK) {
      drape_cloth_params back;
      drape_cloth_params_init(&back);
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_get_params(g, &back)) == DRAPE_OK, "get after set");
      DRAPE_FUZZ_CHECK(back.substep_hz == c.substep_hz && back.stretch_compliance == c.stretch_compliance &&
                           back.max_speed == c.max_speed,
                       "params come back as set");
    } else if (live) {
      drape_cloth_params after;
      drape_cloth_params_init(&after);
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_get_params(g, &after)) == DRAPE_OK, "get after refused set");
      DRAPE_FUZZ_CHECK(std::memcmp(&before, &after, sizeof before) == 0, "a refused set_params changes nothing");
    }
  }

  void destroyGarment() {
    const int s = in.u8() % kGarments;
    if (!gar[s].handle) {
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_destroy(nullptr)) == DRAPE_OK, "destroy(NULL) is OK");
      return;
    }
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_destroy(gar[s].handle)) == DRAPE_OK, "destroying a live garment");
    dead_garments.push_back(gar[s].handle);
    gar[s] = Gar{};
  }

  // Capacity near `need` (below, equal, above) or 0; buffers are allocated to what we declare.
  uint32_t capacity(uint32_t need) {
    const uint8_t k = in.u8();
    if (k < 200) return need;
    if (k < 220) return need + (k - 200) % 3;
    if (k < 240) return need > 0 ? need - 1 : 0;
    return 0;
  }

  void checkGarment(drape_garment* g) {
    uint32_t nv = 0, ni = 0;
    if (DRAPE_FUZZ_CALL(drape_garment_get_mesh_size(g, &nv, &ni)) != DRAPE_OK) return;
    const float* xyzw = nullptr;
    uint32_t n = 0;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_view_positions(g, &xyzw, &n)) == DRAPE_OK && n == nv, "view");
    DRAPE_FUZZ_CHECK(allFinite(xyzw, 4u * n), "garment positions finite");
    drape_garment_stats st;
    st.struct_size = sizeof st;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_get_stats(g, &st)) == DRAPE_OK, "stats");
    DRAPE_FUZZ_CHECK(st.nan_reset == 0, "no NaN reset (drape_garment_stats.nan_reset)");
  }

  void readGarment() {
    drape_garment* g = pickGarment();
    uint32_t nv = 0, ni = 0;
    const bool live = DRAPE_FUZZ_CALL(drape_garment_get_mesh_size(g, &nv, &ni)) == DRAPE_OK;
    const uint32_t vc = capacity(nv), ic = capacity(ni);
    const uint8_t which = in.u8();
    std::vector<drape_vec3> pos(vc + 1), nrm(vc + 1);
    std::vector<uint32_t> idx(ic + 1);
    if (DRAPE_FUZZ_CALL(drape_garment_read_mesh(g, (which & 1) ? pos.data() : nullptr, (which & 2) ? nrm.data() : nullptr,
                                                vc, (which & 4) ? idx.data() : nullptr, ic)) == DRAPE_OK) {
      DRAPE_FUZZ_CHECK(live, "read_mesh OK on a garment whose size query failed");
      for (uint32_t i = 0; i < nv; ++i) {
        if (which & 1) DRAPE_FUZZ_CHECK(finite3(pos[i]), "garment positions finite");
        if (which & 2) DRAPE_FUZZ_CHECK(finite3(nrm[i]), "garment normals finite");
      }
      if (which & 4)
        for (uint32_t i = 0; i < ni; ++i) DRAPE_FUZZ_CHECK(idx[i] < nv, "garment index in range");
    }
    if (DRAPE_FUZZ_CALL(drape_garment_read_rest_positions(g, pos.data(), vc)) == DRAPE_OK)
      for (uint32_t i = 0; i < nv; ++i) DRAPE_FUZZ_CHECK(finite3(pos[i]), "rest positions finite");
    drape_garment_accuracy a;
    a.struct_size = (which & 8) ? in.u8() : sizeof a;
    if (DRAPE_FUZZ_CALL(drape_garment_measure(g, &a)) == DRAPE_OK) {
      DRAPE_FUZZ_CHECK(std::isfinite(a.max_stretch) && std::isfinite(a.p99_stretch) && std::isfinite(a.mean_stretch) &&
                           std::isfinite(a.body_penetration_p99_mm) && std::isfinite(a.body_penetration_max_mm) &&
                           std::isfinite(a.deeper_than_2mm),
                       "garment accuracy finite");
      if (a.struct_size == sizeof a) {
        DRAPE_FUZZ_CHECK(a.openings_off <= a.openings, "openings off <= openings");
        DRAPE_FUZZ_CHECK(a.inside_body >= a.deeper_than_2mm && a.inside_body <= 1.0f, "inside the body: a fraction, at least those deeper than 2 mm");
      }
    }
    if (live) checkGarment(g);
  }

  void readBody() {
    drape_context* h = pickContext();
    uint32_t nv = 0, ni = 0;
    const bool live = DRAPE_FUZZ_CALL(drape_context_get_body_mesh_size(h, &nv, &ni)) == DRAPE_OK;
    const uint32_t vc = capacity(nv), ic = capacity(ni);
    const uint8_t which = in.u8();
    std::vector<drape_vec3> pos(vc + 1), nrm(vc + 1);
    std::vector<uint32_t> idx(ic + 1);
    if (DRAPE_FUZZ_CALL(drape_context_read_body_mesh(h, (which & 1) ? pos.data() : nullptr,
                                                     (which & 2) ? nrm.data() : nullptr, vc,
                                                     (which & 4) ? idx.data() : nullptr, ic)) == DRAPE_OK) {
      DRAPE_FUZZ_CHECK(live, "read_body_mesh OK where the size query failed");
      for (uint32_t i = 0; i < nv; ++i) {
        if (which & 1) DRAPE_FUZZ_CHECK(finite3(pos[i]), "body positions finite");
        if (which & 2) DRAPE_FUZZ_CHECK(finite3(nrm[i]), "body normals finite");
      }
      if (which & 4)
        for (uint32_t i = 0; i < ni; ++i) DRAPE_FUZZ_CHECK(idx[i] < nv, "body index in range");
    }
    drape_vec3 sk[24];
    uint32_t count = 0;
    if (DRAPE_FUZZ_CALL(drape_context_read_skeleton(h, sk, capacity(21), &count)) == DRAPE_OK) {
      DRAPE_FUZZ_CHECK(count == 21, "21 canonical joints");
      for (uint32_t i = 0; i < 21; ++i) DRAPE_FUZZ_CHECK(finite3(sk[i]), "skeleton finite");
    }
    uint32_t ne = 0;
    if (DRAPE_FUZZ_CALL(drape_context_get_ellipsoid_count(h, &ne)) == DRAPE_OK) {
      const uint32_t ec = capacity(ne);
      std::vector<drape_ellipsoid> e(ec + 1);
      if (DRAPE_FUZZ_CALL(drape_context_read_ellipsoids(h, e.data(), ec, nullptr)) == DRAPE_OK) {
        for (uint32_t i = 0; i < ne; ++i)
          DRAPE_FUZZ_CHECK(finite3(e[i].centre) && finite3(e[i].axis_x) && finite3(e[i].axis_y) &&
                               finite3(e[i].axis_z) && finite3(e[i].radii) && e[i].radii.x > 0 && e[i].radii.y > 0 &&
                               e[i].radii.z > 0,
                           "ellipsoids finite with positive radii");
      }
      std::vector<float> m(16u * (ec + 1));
      if (DRAPE_FUZZ_CALL(drape_context_read_ellipsoid_matrices(h, m.data(), ec, nullptr)) == DRAPE_OK)
        DRAPE_FUZZ_CHECK(allFinite(m.data(), 16u * ne), "ellipsoid matrices finite");
    }
    if ((which & 0x28) == 0x28 && fidelity < kMaxFidelity) {  // a diagnostic: only now and then
      ++fidelity;
      drape_proxy_fidelity f;
      f.struct_size = sizeof f;
      if (DRAPE_FUZZ_CALL(drape_context_measure_proxy_fidelity(h, &f)) == DRAPE_OK)
        DRAPE_FUZZ_CHECK(std::isfinite(f.body_to_proxy_max_mm) && std::isfinite(f.proxy_to_body_max_mm) &&
                             std::isfinite(f.outside_fraction),
                         "fidelity finite");
    }
    drape_frame_stats fs;
    fs.struct_size = (which & 16) ? in.u8() : sizeof fs;
    if (DRAPE_FUZZ_CALL(drape_context_get_frame_stats(h, &fs)) == DRAPE_OK && fs.updates > 0)
      DRAPE_FUZZ_CHECK(std::isfinite(fs.body_volume_l) && fs.body_volume_l > 0.0f, "body volume finite and positive");
    pipeline(h, which);
  }

  // The adaptive pipeline (docs/adaptive.md): options from the input (flags 0-2, values nasty),
  // a refused set changes nothing, the skip counters stay consistent, a wake is always accepted.
  void pipeline(drape_context* h, uint8_t which) {
    drape_pipeline_options before, o;
    drape_pipeline_options_init(&before);
    const bool live = DRAPE_FUZZ_CALL(drape_context_get_pipeline_options(h, &before)) == DRAPE_OK;
    if (which & 0x80) {
      drape_pipeline_options_init(&o);
      o.cull_proxies = in.u8() % 3;
      o.stages_on_demand = in.u8() % 3;
      o.sleep = in.u8() % 3;
      if (in.u8() & 1) o.sleep_delay_s = in.nasty();
      if (in.u8() & 1) o.sleep_distance_m = in.nasty();
      if (in.u8() & 1) o.sleep_speed_m_s = in.nasty();
      if (in.u8() & 1) o.reach_margin_m = in.nasty();
      if (DRAPE_FUZZ_CALL(drape_context_set_pipeline_options(h, &o)) != DRAPE_OK && live) {
        drape_pipeline_options after;
        drape_pipeline_options_init(&after);
        DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_get_pipeline_options(h, &after)) == DRAPE_OK, "get options");
        DRAPE_FUZZ_CHECK(std::memcmp(&before, &after, sizeof before) == 0, "a refused set_pipeline_options changes nothing");
      }
    }
    if (which & 0x40) DRAPE_FUZZ_CHECK((DRAPE_FUZZ_CALL(drape_context_wake(h)) == DRAPE_OK) == live, "wake a live context");
    drape_skip_stats k;
    std::memset(&k, 0, sizeof k);
    k.struct_size = sizeof k;
    if (DRAPE_FUZZ_CALL(drape_context_get_skip_stats(h, &k)) == DRAPE_OK)
      DRAPE_FUZZ_CHECK(k.proxies_built <= k.proxies_available && k.garments_asleep <= k.garments &&
                           k.frames_slept <= k.steps && k.garment_steps_slept >= k.frames_slept,
                       "skip counters consistent");
  }

  void run() {
    for (int op = 0; op < kMaxOps && !in.empty(); ++op) {
      switch (in.u8() % 16) {
        case 0: createContext(); break;
        case 1: destroyContext(); break;
        case 2: case 3: push(false); break;
        case 4: push(true); break;
        case 5: update(); break;
        case 6: case 7: step(); break;
        case 8: setShape(); break;
        case 9: addTemplate(); break;
        case 10: addMesh(); break;
        case 11: setParams(); break;
        case 12: readGarment(); break;
        case 13: readBody(); break;
        case 14: destroyGarment(); break;
        case 15: {  // the stale and never-created handles must be refused
          drape_context* h = pickContext();
          if (!slotOf(h) && h) {
            DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_update(h)) == DRAPE_ERROR_INVALID_HANDLE, "stale context");
            DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_destroy(h)) == DRAPE_ERROR_INVALID_HANDLE, "stale destroy");
          }
          break;
        }
      }
    }
    // Tear down in an order chosen by the input: garments first or contexts first.
    const bool garments_first = in.u8() & 1;
    if (garments_first)
      for (Gar& g : gar)
        if (g.handle) DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_destroy(g.handle)) == DRAPE_OK, "garment destroy");
    for (int s = kContexts - 1; s >= 0; --s)
      if (ctx[s].handle) DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_destroy(ctx[s].handle)) == DRAPE_OK, "destroy");
    if (!garments_first)
      for (Gar& g : gar)
        if (g.handle)
          DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_destroy(g.handle)) == DRAPE_ERROR_INVALID_HANDLE,
                           "a garment dies with its context");
  }
};

}  // namespace

DRAPE_FUZZ_TARGET(capi) {
  Machine m(Bytes(data, size));
  m.run();
  return 0;
}
