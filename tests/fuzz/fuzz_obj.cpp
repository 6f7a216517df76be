// Fuzz target: OBJ garments through drape_context_add_garment_obj_memory. The input is the OBJ
// text. A fresh context on a synthetic person (one tracked frame) takes it with the default fit
// and a short dressing; when accepted, the garment is read back, stepped three frames, measured
// and destroyed, and every output must be finite.
#include "fuzz_support.h"

#include <vector>

using namespace drape_fuzz;

namespace {

drape_result pushFrame(drape_context* ctx, double t) {
  drape_joint j[25];
  drape_fuzz::standingPose25(t, 0.0f, j);
  drape_skeleton_frame f;
  std::memset(&f, 0, sizeof f);
  f.struct_size = sizeof f;
  f.layout = DRAPE_LAYOUT_KINECT2;
  f.joint_count = 25;
  f.timestamp_s = t;
  f.joints = j;
  return drape_context_push_skeleton(ctx, &f);
}

}  // namespace

DRAPE_FUZZ_TARGET(obj) {
  if (size > (1u << 19)) return 0;  // MakeHuman garments are 170-230 KB
  drape_context* ctx = nullptr;
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_create(nullptr, &ctx)) == DRAPE_OK, "context create");
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(pushFrame(ctx, 0.0)) == DRAPE_OK, "first frame");
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_update(ctx)) == DRAPE_OK, "first update");

  drape_garment_desc desc;
  drape_garment_desc_init(&desc);
  desc.dress_time_s = 0.1f;  // keeps an execution in the milliseconds
  drape_garment* g = nullptr;
  const drape_result r =
      DRAPE_FUZZ_CALL(drape_context_add_garment_obj_memory(ctx, data, size, nullptr, &desc, nullptr, &g));
  if (r != DRAPE_OK) {
    DRAPE_FUZZ_CHECK(g == nullptr, "a refused garment leaves *out_garment alone");
  } else {
    uint32_t nv = 0, ni = 0;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_get_mesh_size(g, &nv, &ni)) == DRAPE_OK, "mesh size");
    DRAPE_FUZZ_CHECK(nv >= 3 && ni >= 3 && ni % 3 == 0, "a garment has at least a triangle");
    std::vector<drape_vec3> pos(nv), nrm(nv), rest(nv);
    std::vector<uint32_t> idx(ni);
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_read_mesh(g, pos.data(), nrm.data(), nv, idx.data(), ni)) ==
                         DRAPE_OK,
                     "read the dressed mesh");
    for (uint32_t i : idx) DRAPE_FUZZ_CHECK(i < nv, "index within the vertex count");
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_read_rest_positions(g, rest.data(), nv)) == DRAPE_OK, "rest");
    for (uint32_t i = 0; i < nv; ++i) {
      DRAPE_FUZZ_CHECK(finite3(pos[i]) && finite3(nrm[i]) && finite3(rest[i]), "dressed garment finite");
    }
    for (int k = 1; k <= 3; ++k) {
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(pushFrame(ctx, k / 30.0)) == DRAPE_OK, "frame");
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_step(ctx, 1.0f / 30.0f)) == DRAPE_OK, "step");
      const float* xyzw = nullptr;
      uint32_t n = 0;
      DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_view_positions(g, &xyzw, &n)) == DRAPE_OK && n == nv, "view");
      DRAPE_FUZZ_CHECK(allFinite(xyzw, 4u * n), "stepped garment finite");
    }
    drape_garment_stats s;
    s.struct_size = sizeof s;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_get_stats(g, &s)) == DRAPE_OK, "stats");
    DRAPE_FUZZ_CHECK(s.nan_reset == 0, "no NaN reset");
    drape_garment_accuracy a;
    a.struct_size = sizeof a;
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_measure(g, &a)) == DRAPE_OK, "measure");
    DRAPE_FUZZ_CHECK(std::isfinite(a.max_stretch) && std::isfinite(a.p99_stretch) && std::isfinite(a.mean_stretch),
                     "stretch finite");
    DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_garment_destroy(g)) == DRAPE_OK, "garment destroy");
  }
  DRAPE_FUZZ_CHECK(DRAPE_FUZZ_CALL(drape_context_destroy(ctx)) == DRAPE_OK, "context destroy");
  return 0;
}
