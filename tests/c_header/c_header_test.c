/* The public header compiled as plain C99 (-Wall -Wextra -Wpedantic -Werror) and used the way a
 * C host would: against the shared library only, through <drape/drape.h>.
 *
 * A synthetic Kinect v2 person stands 2.5 m in front of the sensor, facing it, and sways a little
 * for 40 frames at 30 Hz. The program creates a context, sets a body shape, pushes and updates
 * every frame, reads the body mesh through the size query, checks it, checks that a bad call
 * fails with a message, and destroys everything. Exit status 0 on success, 1 (after saying what
 * failed) otherwise. */
#include <drape/drape.h>

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_failures = 0;

#define CHECK(cond)                                                                 \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);      \
      ++g_failures;                                                                 \
    }                                                                               \
  } while (0)

/* A call that must succeed; on failure prints the result name and the library's message. */
#define CHECK_OK(call)                                                              \
  do {                                                                              \
    drape_result r_ = (call);                                                       \
    if (r_ != DRAPE_OK) {                                                           \
      fprintf(stderr, "%s:%d: %s -> %s: %s\n", __FILE__, __LINE__, #call,           \
              drape_result_name(r_), drape_last_error());                           \
      ++g_failures;                                                                 \
    }                                                                               \
  } while (0)

enum { kJoints = 25, kFrames = 40 };

/* Kinect v2 JointType order, metres, camera space (+Y up, +Z away from the sensor, the
 * subject's right at +X). SpineBase at (0, 0, 2.5); the head 0.75 m above it. */
static const float kStanding[kJoints][3] = {
    {0.00f, 0.00f, 2.50f},   /*  0 SpineBase */
    {0.00f, 0.30f, 2.50f},   /*  1 SpineMid */
    {0.00f, 0.60f, 2.50f},   /*  2 Neck */
    {0.00f, 0.75f, 2.48f},   /*  3 Head */
    {-0.18f, 0.50f, 2.50f},  /*  4 ShoulderLeft */
    {-0.24f, 0.24f, 2.50f},  /*  5 ElbowLeft */
    {-0.27f, 0.01f, 2.48f},  /*  6 WristLeft */
    {-0.28f, -0.06f, 2.47f}, /*  7 HandLeft */
    {0.18f, 0.50f, 2.50f},   /*  8 ShoulderRight */
    {0.24f, 0.24f, 2.50f},   /*  9 ElbowRight */
    {0.27f, 0.01f, 2.48f},   /* 10 WristRight */
    {0.28f, -0.06f, 2.47f},  /* 11 HandRight */
    {-0.08f, -0.02f, 2.50f}, /* 12 HipLeft */
    {-0.09f, -0.45f, 2.52f}, /* 13 KneeLeft */
    {-0.09f, -0.85f, 2.55f}, /* 14 AnkleLeft */
    {-0.09f, -0.92f, 2.45f}, /* 15 FootLeft */
    {0.08f, -0.02f, 2.50f},  /* 16 HipRight */
    {0.09f, -0.45f, 2.52f},  /* 17 KneeRight */
    {0.09f, -0.85f, 2.55f},  /* 18 AnkleRight */
    {0.09f, -0.92f, 2.45f},  /* 19 FootRight */
    {0.00f, 0.52f, 2.50f},   /* 20 SpineShoulder */
    {-0.29f, -0.14f, 2.47f}, /* 21 HandTipLeft */
    {-0.25f, -0.08f, 2.43f}, /* 22 ThumbLeft */
    {0.29f, -0.14f, 2.47f},  /* 23 HandTipRight */
    {0.25f, -0.08f, 2.43f},  /* 24 ThumbRight */
};

static int vecFinite(const drape_vec3* v) { return isfinite(v->x) && isfinite(v->y) && isfinite(v->z); }

int main(void) {
  drape_context_desc desc;
  drape_body_shape shape;
  drape_context* ctx = NULL;
  drape_joint joints[kJoints];
  drape_skeleton_frame frame;
  drape_frame_stats stats;
  uint32_t vertex_count = 0, index_count = 0, i, f;
  drape_vec3* positions = NULL;
  drape_vec3* normals = NULL;
  uint32_t* indices = NULL;
  drape_ellipsoid* ellipsoids = NULL;
  uint32_t ellipsoid_count = 0;
  drape_result bad;
  const char* message;
  char expected_version[32];

  /* Version: the header and the library agree. */
  CHECK((drape_version() >> 22) == DRAPE_VERSION_MAJOR);
  CHECK(drape_version() == DRAPE_VERSION);
  sprintf(expected_version, "%d.%d.%d", DRAPE_VERSION_MAJOR, DRAPE_VERSION_MINOR, DRAPE_VERSION_PATCH);
  CHECK(drape_version_string() != NULL && strcmp(drape_version_string(), expected_version) == 0);
  CHECK(strcmp(drape_result_name(DRAPE_OK), "DRAPE_OK") == 0);

  /* Layout guarantees a C host relies on. */
  CHECK(sizeof(drape_vec3) == 12);
  CHECK(sizeof(drape_joint) == 16);
  CHECK(sizeof(drape_result) == 4);

  /* Context with a desc from drape_context_desc_init. */
  CHECK_OK(drape_context_desc_init(&desc));
  CHECK(desc.struct_size == sizeof(drape_context_desc));
  CHECK(desc.arms_clear_torso == 1);
  CHECK(offsetof(drape_context_desc, arms_clear_torso) == DRAPE_CONTEXT_DESC_SIZE_V1);
  /* The sized init writes only the size it is given (a first-layout host's 64 bytes). */
  {
    drape_context_desc first;
    memset(&first, 0x5A, sizeof(first));
    CHECK_OK(drape_context_desc_init_sized(&first, DRAPE_CONTEXT_DESC_SIZE_V1));
    CHECK(first.struct_size == DRAPE_CONTEXT_DESC_SIZE_V1);
    CHECK(first.ring_points == desc.ring_points);
    CHECK(first.arms_clear_torso == 0x5A5A5A5A);
  }
  CHECK(offsetof(drape_cloth_params, collision_stride) == DRAPE_CLOTH_PARAMS_SIZE_V1);
  CHECK(offsetof(drape_cloth_params, strain_limit_passes) == DRAPE_CLOTH_PARAMS_SIZE_V2);
  CHECK(sizeof(drape_cloth_params) == DRAPE_CLOTH_PARAMS_SIZE_V2 + 4);
  CHECK_OK(drape_context_create(&desc, &ctx));
  if (ctx == NULL) {
    fprintf(stderr, "no context: giving up\n");
    return 1;
  }

  /* Body shape: 1.75 m, 70 kg, a given chest girth, the rest predicted. */
  CHECK_OK(drape_body_shape_init(&shape));
  shape.sex = DRAPE_SEX_MALE;
  shape.height_m = 1.75f;
  shape.weight_kg = 70.0f;
  shape.chest_mm = 980.0f;
  CHECK_OK(drape_context_set_body_shape(ctx, &shape));
  memset(&shape, 0, sizeof(shape));
  shape.struct_size = sizeof(shape);
  CHECK_OK(drape_context_get_body_shape(ctx, &shape));
  CHECK(shape.sex == DRAPE_SEX_MALE);
  CHECK(shape.height_m == 1.75f);
  CHECK(fabsf(shape.chest_mm - 980.0f) < 0.01f);
  CHECK(shape.waist_mm > 0.0f && shape.neck_mm > 0.0f);

  /* Frames: ~40 at 30 Hz, the person swaying 3 cm side to side. */
  memset(&frame, 0, sizeof(frame));
  frame.struct_size = sizeof(frame);
  frame.layout = DRAPE_LAYOUT_KINECT2;
  frame.joint_count = kJoints;
  frame.joints = joints;
  frame.orientations = NULL;
  for (f = 0; f < kFrames; ++f) {
    const float sway = 0.03f * (float)((int)(f % 10) - 5) / 5.0f;
    for (i = 0; i < kJoints; ++i) {
      joints[i].position.x = kStanding[i][0] + sway;
      joints[i].position.y = kStanding[i][1];
      joints[i].position.z = kStanding[i][2];
      joints[i].tracking_state = DRAPE_TRACKING_TRACKED;
    }
    frame.timestamp_s = 0.5 + (double)f / 30.0;
    CHECK_OK(drape_context_push_skeleton(ctx, &frame));
    CHECK_OK(drape_context_update(ctx));
  }

  /* Body mesh through the size query. */
  CHECK_OK(drape_context_get_body_mesh_size(ctx, &vertex_count, &index_count));
  CHECK(vertex_count > 0 && index_count > 0 && index_count % 3 == 0);
  positions = (drape_vec3*)malloc(sizeof(drape_vec3) * (vertex_count ? vertex_count : 1));
  normals = (drape_vec3*)malloc(sizeof(drape_vec3) * (vertex_count ? vertex_count : 1));
  indices = (uint32_t*)malloc(sizeof(uint32_t) * (index_count ? index_count : 1));
  if (!positions || !normals || !indices) {
    fprintf(stderr, "out of memory\n");
    return 1;
  }
  CHECK_OK(drape_context_read_body_mesh(ctx, positions, normals, vertex_count, indices, index_count));
  for (i = 0; i < vertex_count; ++i) {
    if (!vecFinite(&positions[i]) || !vecFinite(&normals[i])) {
      fprintf(stderr, "vertex %u is not finite\n", (unsigned)i);
      ++g_failures;
      break;
    }
  }
  for (i = 0; i < index_count; ++i) {
    if (indices[i] >= vertex_count) {
      fprintf(stderr, "index %u = %u >= vertex count %u\n", (unsigned)i, (unsigned)indices[i], (unsigned)vertex_count);
      ++g_failures;
      break;
    }
  }
  /* The body stands around the pelvis (within 1.5 m of SpineBase, 2.5 m away). */
  for (i = 0; i < vertex_count; ++i) {
    if (fabsf(positions[i].z - 2.5f) > 1.5f || fabsf(positions[i].y) > 1.5f) {
      fprintf(stderr, "vertex %u at (%g, %g, %g) is far from the person\n", (unsigned)i, positions[i].x,
              positions[i].y, positions[i].z);
      ++g_failures;
      break;
    }
  }

  /* Tracking ellipsoids through their count query. */
  CHECK_OK(drape_context_get_ellipsoid_count(ctx, &ellipsoid_count));
  CHECK(ellipsoid_count > 0);
  ellipsoids = (drape_ellipsoid*)malloc(sizeof(drape_ellipsoid) * (ellipsoid_count ? ellipsoid_count : 1));
  if (!ellipsoids) {
    fprintf(stderr, "out of memory\n");
    return 1;
  }
  CHECK_OK(drape_context_read_ellipsoids(ctx, ellipsoids, ellipsoid_count, NULL));
  for (i = 0; i < ellipsoid_count; ++i) {
    if (!vecFinite(&ellipsoids[i].centre) || !vecFinite(&ellipsoids[i].radii) || ellipsoids[i].radii.x <= 0.0f ||
        ellipsoids[i].chain < 0 || ellipsoids[i].chain > 5) {
      fprintf(stderr, "ellipsoid %u is malformed\n", (unsigned)i);
      ++g_failures;
      break;
    }
  }
  free(ellipsoids);

  memset(&stats, 0, sizeof(stats));
  stats.struct_size = sizeof(stats);
  CHECK_OK(drape_context_get_frame_stats(ctx, &stats));
  CHECK(stats.frames_accepted == kFrames);
  CHECK(stats.updates == kFrames);
  CHECK(stats.frames_rejected == 0);
  CHECK(stats.calibrated == 1);
  CHECK(stats.body_volume_l > 0.0f);

  /* A deliberately bad call: a frame whose timestamp goes back in time. It fails with an error
   * code and a message, and is counted as rejected. */
  frame.timestamp_s = 0.0;
  bad = drape_context_push_skeleton(ctx, &frame);
  CHECK(bad == DRAPE_ERROR_TIMESTAMP);
  message = drape_last_error();
  CHECK(message != NULL && message[0] != '\0');
  /* ... and a buffer one vertex too small, with a NULL context for good measure. */
  CHECK(drape_context_read_body_mesh(ctx, positions, NULL, vertex_count - 1, NULL, 0) == DRAPE_ERROR_BUFFER_TOO_SMALL);
  CHECK(drape_context_update(NULL) == DRAPE_ERROR_NULL_ARGUMENT);
  message = drape_last_error();
  CHECK(message != NULL && strstr(message, "drape_context_update") != NULL);
  CHECK_OK(drape_context_get_frame_stats(ctx, &stats));
  CHECK(stats.frames_rejected == 1);

  free(positions);
  free(normals);
  free(indices);
  CHECK_OK(drape_context_destroy(ctx));
  CHECK(drape_context_destroy(ctx) == DRAPE_ERROR_INVALID_HANDLE); /* stale now */
  CHECK_OK(drape_context_destroy(NULL));

  if (g_failures) {
    fprintf(stderr, "c_header_test: %d check(s) failed\n", g_failures);
    return 1;
  }
  printf("c_header_test: OK (drape %s, %u vertices, %u indices)\n", drape_version_string(), (unsigned)vertex_count,
         (unsigned)index_count);
  return 0;
}
