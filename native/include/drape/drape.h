/*
 * drape.h — the whole public C ABI of Drape, a real-time virtual dressing engine.
 *
 * Conventions (read once, they hold for every function below):
 *  - Prefix `drape_`, snake_case. Every function returns a drape_result (DRAPE_OK = 0) unless it is
 *    a pure query documented otherwise. On failure, drape_last_error() returns a message for the
 *    calling thread's last failed call; the message is never needed to tell that a call failed.
 *  - Handles are opaque pointers. A destroyed, never-created or foreign pointer passed as a handle
 *    returns DRAPE_ERROR_INVALID_HANDLE; it is never dereferenced.
 *  - `*_desc`/`*_shape` structs start with `struct_size`: fill them with their `*_init` function
 *    (sets defaults and struct_size) and then change the fields you need. A struct_size smaller than
 *    the first released version of the struct is rejected, so uninitialised structs are caught;
 *    fields added to a struct later are appended, and a caller built with the earlier header
 *    (a smaller struct_size) gets their defaults. An init function fills sizeof of the library's
 *    struct, more than such a caller has, so a struct that grows keeps its exported `_init` at the
 *    size it had and gains an `_init_sized` that this header's `_init` maps to with the caller's
 *    sizeof (drape_cloth_params since collision_stride; drape_context_desc, whose exported init
 *    fills the 72 bytes the struct had when its sized init came: 8 more than a host built against
 *    its 64-byte first layout has, a hazard left only to such old binaries).
 *  - Buffers: the caller allocates and passes (pointer, capacity); the library writes and never keeps
 *    the pointer. Size queries tell the capacity needed. Nothing the caller owns is modified when a
 *    call fails.
 *  - Units: metres, seconds, kilograms; girths in millimetres. Positions in a right-handed camera
 *    space. Vectors are {float x, y, z}, layout-compatible with Unity's Vector3.
 *  - Threading: one thread at a time per drape_context (the caller serialises calls on one context);
 *    different contexts may be used from different threads at the same time. drape_last_error() is
 *    per thread. Functions without a context are safe from any thread.
 *  - No C++ exception, abort or assert crosses this boundary; NaN/Inf inputs are rejected.
 */
#ifndef DRAPE_H
#define DRAPE_H

#include <stddef.h>
#include <stdint.h>

#define DRAPE_VERSION_MAJOR 0
#define DRAPE_VERSION_MINOR 2
#define DRAPE_VERSION_PATCH 0
/* Packed version: major << 22 | minor << 12 | patch (as returned by drape_version()). */
#define DRAPE_MAKE_VERSION(major, minor, patch) \
  ((((uint32_t)(major)) << 22) | (((uint32_t)(minor)) << 12) | ((uint32_t)(patch)))
#define DRAPE_VERSION DRAPE_MAKE_VERSION(DRAPE_VERSION_MAJOR, DRAPE_VERSION_MINOR, DRAPE_VERSION_PATCH)

#if defined(_WIN32)
#  define DRAPE_CALL __cdecl
#  if defined(DRAPE_BUILDING_LIBRARY)
#    define DRAPE_API __declspec(dllexport)
#  else
#    define DRAPE_API __declspec(dllimport)
#  endif
#else
#  define DRAPE_CALL
#  define DRAPE_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/* Results and errors                                                                          */
/* ------------------------------------------------------------------------------------------ */

typedef enum drape_result {
  DRAPE_OK = 0,
  DRAPE_ERROR_NULL_ARGUMENT = 1,     /* a required pointer was NULL */
  DRAPE_ERROR_INVALID_ARGUMENT = 2,  /* a value is malformed (bad struct_size, bad combination) */
  DRAPE_ERROR_INVALID_HANDLE = 3,    /* the handle is not a live object of the expected kind */
  DRAPE_ERROR_BUFFER_TOO_SMALL = 4,  /* capacity below the size query's answer; nothing written */
  DRAPE_ERROR_NONFINITE = 5,         /* a NaN or Inf number was passed */
  DRAPE_ERROR_OUT_OF_RANGE = 6,      /* a number or enum is outside its documented range */
  DRAPE_ERROR_CALL_ORDER = 7,        /* the call needs an earlier one (e.g. read before update) */
  DRAPE_ERROR_TIMESTAMP = 8,         /* a frame's timestamp is not after the previous frame's */
  DRAPE_ERROR_IO = 9,                /* a file could not be opened or read */
  DRAPE_ERROR_PARSE = 10,            /* a file or buffer is not in a format Drape reads */
  DRAPE_ERROR_OUT_OF_MEMORY = 11,
  DRAPE_ERROR_INTERNAL = 12,         /* a bug in Drape: please report with drape_last_error() */
  DRAPE_RESULT_FORCE32 = 0x7fffffff
} drape_result;

/* Static name of a result code ("DRAPE_OK", ...). Never NULL. Any thread. */
DRAPE_API const char* DRAPE_CALL drape_result_name(drape_result result);

/* Message describing the calling thread's most recent failed call ("" if none). The string is
 * owned by the library and valid until the next failing call on this thread. Any thread. */
DRAPE_API const char* DRAPE_CALL drape_last_error(void);

/* ------------------------------------------------------------------------------------------ */
/* Version                                                                                     */
/* ------------------------------------------------------------------------------------------ */

/* The library's packed version (DRAPE_MAKE_VERSION). Compare its major part with
 * DRAPE_VERSION_MAJOR to detect a mismatched binary. Any thread. */
DRAPE_API uint32_t DRAPE_CALL drape_version(void);
/* "major.minor.patch", static. Any thread. */
DRAPE_API const char* DRAPE_CALL drape_version_string(void);

/* ------------------------------------------------------------------------------------------ */
/* Basic types                                                                                 */
/* ------------------------------------------------------------------------------------------ */

typedef struct drape_vec3 { float x, y, z; } drape_vec3;
typedef struct drape_quat { float x, y, z, w; } drape_quat;

/* Sensor joint layouts. Joint order is the sensor SDK's own (docs/skeleton.md lists them). */
typedef enum drape_layout {
  DRAPE_LAYOUT_AUTO = 0,     /* only where documented (recording readers) */
  DRAPE_LAYOUT_KINECT1 = 1,  /* 20 joints, NUI_SKELETON_POSITION_INDEX order */
  DRAPE_LAYOUT_KINECT2 = 2,  /* 25 joints, Kinect SDK 2.0 JointType order */
  DRAPE_LAYOUT_AZURE = 3,    /* 32 joints, k4abt_joint_id order; convert millimetres to metres */
  DRAPE_LAYOUT_FORCE32 = 0x7fffffff
} drape_layout;

typedef enum drape_tracking_state {
  DRAPE_TRACKING_NOT_TRACKED = 0,
  DRAPE_TRACKING_INFERRED = 1,
  DRAPE_TRACKING_TRACKED = 2,
  DRAPE_TRACKING_FORCE32 = 0x7fffffff
} drape_tracking_state;

/* One joint as the sensor reports it. 16 bytes. */
typedef struct drape_joint {
  drape_vec3 position;    /* metres, camera space */
  int32_t tracking_state; /* drape_tracking_state */
} drape_joint;

/* ------------------------------------------------------------------------------------------ */
/* Context                                                                                     */
/* ------------------------------------------------------------------------------------------ */

typedef struct drape_context drape_context;

typedef enum drape_filter {
  DRAPE_FILTER_NONE = 0,
  DRAPE_FILTER_ONE_EURO = 1,           /* Casiez et al. 2012; default */
  DRAPE_FILTER_DOUBLE_EXPONENTIAL = 2, /* Kinect SDK-style Holt filter */
  DRAPE_FILTER_FORCE32 = 0x7fffffff
} drape_filter;

typedef enum drape_proxy_rule {
  DRAPE_PROXY_RULE_PAPER = 0, /* the paper's eq. 5-6: per torso ring, one per limb bone */
  DRAPE_PROXY_RULE_DRAPE = 1, /* per ring everywhere, sized to close the gaps (docs/proxies.md) */
  DRAPE_PROXY_RULE_FORCE32 = 0x7fffffff
} drape_proxy_rule;

/* What proportions garments are cut for (drape_context_desc.garment_fit): those whose own cut
 * (drape_garment_desc.cut) is DRAPE_GARMENT_CUT_CONTEXT, the default. */
typedef enum drape_garment_fit {
  /* The body shape's standard proportions (drape_context_set_body_shape), whatever the skeleton.
   * Default. */
  DRAPE_GARMENT_FIT_SHAPE = 0,
  /* The tracked person's. At the first pose of a calibrating tracker, when every limb joint of it
   * is tracked and no such garment has stepped yet, the garments cut for the skeleton are cut for
   * that pose's bones before their first step (and at any rate when the shape is too small for the
   * person: DRAPE_GARMENT_CUT_BY_KIND); else they are cut for the shape's standard proportions until
   * the tracker has calibrated the bone lengths (calibration_frames). At the calibration every
   * garment cut for the skeleton is cut again for this person: the rest pose takes their bone lengths and their torso's
   * geometry (spine, hip and shoulder joints) averaged over the calibration window, template
   * garments are made again on it with their first layout, OBJ garments carried to it
   * (drape_garment_stats.refits counts it; particles and triangles stay, the rest shape changes).
   * The new cut is made in the calibration's step and dressed over the next steps (two 1/30 s
   * frames a step beside the old cut, which the host goes on seeing), then swapped in: with the
   * default dress time, 9 steps after the calibration's (drape_garment_desc.dress_time_s).
   * No refit when the person's rest pose is within 1 cm of the one the garments were cut for (the
   * standard one, or the first pose's: docs/garments.md, "Cut for the first pose"). Less stretch on most
   * shared takes at 2 000 particles, more on some (skirts on the Kinect takes, coarse garments):
   * docs/garments.md. */
  DRAPE_GARMENT_FIT_SKELETON = 1,
  DRAPE_GARMENT_FIT_FORCE32 = 0x7fffffff
} drape_garment_fit;

typedef struct drape_context_desc {
  uint32_t struct_size;          /* sizeof(drape_context_desc), set by drape_context_desc_init */
  uint32_t ring_points;          /* K, points per feature ring: multiple of 4 in [8, 256]; 20 */
  uint32_t rings_per_segment;    /* extra rings between two ring stations: [0, 16]; default 1 */
  uint32_t calibration_frames;   /* frames over which bone lengths are measured, then held:
                                    [1, 100000]; default 30 */
  int32_t filter;                /* drape_filter; default DRAPE_FILTER_ONE_EURO */
  float filter_min_cutoff_hz;    /* One-Euro minimum cutoff (Hz), [0.001, 1000]; 0.5 */
  float filter_beta;             /* One-Euro speed coefficient, [0, 1000]; 6 */
  float filter_d_cutoff_hz;      /* One-Euro derivative cutoff (Hz), [0.001, 1000]; 1 */
  float smoothing;               /* double exponential: [0, 0.999]; 0.5 */
  float correction;              /* double exponential: [0, 1]; 0.5 */
  float prediction;              /* double exponential, in 30 Hz frames: [0, 10]; 0.5 */
  float jitter_radius_m;         /* double exponential: [0, 10]; 0.05 */
  float max_deviation_m;         /* double exponential: [0, 10]; 0.04 */
  float teleport_distance_m;     /* a pelvis jump beyond this (plus what 5 m/s covers in the
                                    frame's dt) is reported as a teleport; (0, 100]; 0.5 */
  int32_t proxy_rule;            /* drape_proxy_rule: how tracking ellipsoids are built;
                                    default DRAPE_PROXY_RULE_DRAPE */
  int32_t garment_fit;           /* drape_garment_fit; default DRAPE_GARMENT_FIT_SHAPE (0) */
  /* The last two fields came after the rest: a desc whose struct_size is
   * DRAPE_CONTEXT_DESC_SIZE_V1 (64, the layout without them) is accepted and gets their defaults. */
  int32_t arms_clear_torso;      /* 1 (default): an arm ring that would run inside the torso (a
                                    hanging arm: sensors put the shoulder joints close to the
                                    spine) is moved out of it, arm_torso_clearance_m apart, so the
                                    sleeve and the torso cloth under it both have room, and a
                                    garment's upper sleeves also collide with the torso, so a
                                    hanging sleeve stays out of it; the body mesh's arms then sit
                                    up to a few centimetres off the tracked joints
                                    (docs/body-model.md, "Arms clear of the torso"; docs/garments.md,
                                    "Sleeves meet the torso").
                                    0: every ring centred on its bone (the paper). 0 or 1 */
  float arm_torso_clearance_m;   /* gap kept between an arm ring and the torso ring beside it,
                                    [0, 0.05] m; 0.01 (two layers of cloth at their 4 mm margin) */
} drape_context_desc;

/* sizeof(drape_context_desc) before arms_clear_torso and arm_torso_clearance_m. */
#define DRAPE_CONTEXT_DESC_SIZE_V1 64u

/* Fills the first `struct_size` bytes of `desc` with the defaults and sets desc->struct_size to it;
 * nothing past them is written. struct_size from DRAPE_CONTEXT_DESC_SIZE_V1 to this library's
 * sizeof(drape_context_desc); outside: DRAPE_ERROR_INVALID_ARGUMENT (a size above it is a header
 * newer than the library) and nothing written. Call it through drape_context_desc_init below. */
DRAPE_API drape_result DRAPE_CALL drape_context_desc_init_sized(drape_context_desc* desc, uint32_t struct_size);
/* The exported drape_context_desc_init fills the struct's second layout (72 bytes, struct_size 72),
 * what hosts built before the sized init have; it stays at that size when the struct grows. Code
 * built with this header calls the sized init with its own sizeof instead, through the inline
 * function and macro below. */
DRAPE_API drape_result DRAPE_CALL drape_context_desc_init(drape_context_desc* desc);
static inline drape_result drape_context_desc_init_current(drape_context_desc* desc) {
  return drape_context_desc_init_sized(desc, (uint32_t)sizeof(drape_context_desc));
}
#define drape_context_desc_init drape_context_desc_init_current

/* Creates a context: one tracked person and (from later versions) their garments. The body starts
 * with the default shape (drape_body_shape_init). `desc` may be NULL for all defaults. On success
 * *out_context owns a new context the caller must release with drape_context_destroy.
 * Thread-safety: any thread. */
DRAPE_API drape_result DRAPE_CALL drape_context_create(const drape_context_desc* desc,
                                                       drape_context** out_context);

/* Destroys a context and every buffer it owns. Views into it become invalid. A NULL context is
 * accepted and ignored (DRAPE_OK); a stale handle returns DRAPE_ERROR_INVALID_HANDLE.
 * Thread-safety: no other call may be running on this context. */
DRAPE_API drape_result DRAPE_CALL drape_context_destroy(drape_context* context);

/* ------------------------------------------------------------------------------------------ */
/* Body shape                                                                                  */
/* ------------------------------------------------------------------------------------------ */

typedef enum drape_sex {
  DRAPE_SEX_UNSPECIFIED = 0,
  DRAPE_SEX_FEMALE = 1,
  DRAPE_SEX_MALE = 2,
  DRAPE_SEX_FORCE32 = 0x7fffffff
} drape_sex;

/* Basic information about the person. Girths are circumferences in millimetres; 0 means
 * "predict from height and weight" (ANSUR II regression, docs/body-shape.md). */
typedef struct drape_body_shape {
  uint32_t struct_size; /* sizeof(drape_body_shape), set by drape_body_shape_init */
  int32_t sex;          /* drape_sex; stored and reported (the regression data is female-only) */
  float height_m;       /* stature, [0.8, 2.5]; default 1.70 */
  float weight_kg;      /* [15, 300]; default 65 */
  float neck_mm, chest_mm, waist_mm, hip_mm;             /* each 0 or [50, 3000] */
  float thigh_mm, calf_mm, upper_arm_mm, forearm_mm;     /* each 0 or [50, 3000] */
} drape_body_shape;

/* Fills `shape` with the default body (1.70 m, 65 kg, girths predicted) and struct_size. */
DRAPE_API drape_result DRAPE_CALL drape_body_shape_init(drape_body_shape* shape);

/* Sets the body shape. The mesh topology does not change; the next update rebuilds the rings.
 * Garments already added are refitted to the new body: each keeps its vertices, triangles,
 * attachments and parameters, its cut is carried to the new body and dressed there (as a new
 * garment is, tens of milliseconds per garment), and the next drape_context_step places it on the
 * tracked person. Setting the same measurements again changes nothing. On failure (a bad value,
 * or a garment that cannot be dressed on the new body) the previous shape and garments are kept.
 * Thread-safety: one thread per context. */
DRAPE_API drape_result DRAPE_CALL drape_context_set_body_shape(drape_context* context,
                                                               const drape_body_shape* shape);

/* Reads the shape in use with every girth resolved: girths the host gave come back exactly as
 * given, predicted ones are filled in.
 * `out_shape->struct_size` must be set by the caller (drape_body_shape_init does). */
DRAPE_API drape_result DRAPE_CALL drape_context_get_body_shape(drape_context* context,
                                                               drape_body_shape* out_shape);

/* ------------------------------------------------------------------------------------------ */
/* Skeleton input                                                                              */
/* ------------------------------------------------------------------------------------------ */

typedef struct drape_skeleton_frame {
  uint32_t struct_size;            /* sizeof(drape_skeleton_frame) */
  int32_t layout;                  /* drape_layout (not AUTO) */
  uint32_t joint_count;            /* must equal the layout's joint count (20, 25, 32) */
  uint32_t reserved;               /* must be 0 (else DRAPE_ERROR_INVALID_ARGUMENT) */
  double timestamp_s;              /* strictly increasing from frame to frame */
  const drape_joint* joints;       /* joint_count joints, in the layout's order */
  const drape_quat* orientations;  /* optional (NULL): joint_count unit quaternions; validated
                                      and stored for the host, the body follows positions */
} drape_skeleton_frame;

/* Validates one frame and queues it for the next drape_context_update. A rejected frame (NULL,
 * bad struct_size, layout or count, NaN/Inf or |coordinate| > 1000 m, tracking state outside
 * 0..2, non-unit orientation, timestamp not after the previous accepted frame) returns an error,
 * is counted in drape_frame_stats.frames_rejected and leaves every bit of
 * the context's state as it was. Pushing twice without an update replaces the queued frame (the
 * newest wins; the replaced one counts as dropped). Thread-safety: one thread per context. */
DRAPE_API drape_result DRAPE_CALL drape_context_push_skeleton(drape_context* context,
                                                              const drape_skeleton_frame* frame);

/* Runs the pipeline on the queued frame: skeleton filter -> feature rings -> body mesh (by
 * default the mesh and the tracking ellipsoids only as far as something needs them: see
 * "Adaptive pipeline").
 * DRAPE_ERROR_CALL_ORDER if no frame was ever accepted. Calling it again without a new frame is
 * allowed and cheap (nothing changes). Thread-safety: one thread per context. */
DRAPE_API drape_result DRAPE_CALL drape_context_update(drape_context* context);

/* Reads the filtered canonical skeleton (21 joints, order in docs/skeleton.md) after an update.
 * positions: capacity >= 21. out_count (optional) receives 21. */
DRAPE_API drape_result DRAPE_CALL drape_context_read_skeleton(drape_context* context,
                                                              drape_vec3* positions,
                                                              uint32_t capacity,
                                                              uint32_t* out_count);

/* ------------------------------------------------------------------------------------------ */
/* Body mesh                                                                                   */
/* ------------------------------------------------------------------------------------------ */

/* Size query: vertex and index counts of the body mesh (fixed for a context: they depend only on
 * ring_points and rings_per_segment). One of the two out pointers may be NULL, not both. */
DRAPE_API drape_result DRAPE_CALL drape_context_get_body_mesh_size(drape_context* context,
                                                                   uint32_t* out_vertex_count,
                                                                   uint32_t* out_index_count);

/* Copies the body mesh of the last update into caller buffers. Each of positions, normals
 * (vertex_capacity entries) and indices (index_capacity entries; counter-clockwise seen from
 * outside, 3 per triangle) may be NULL to skip it; at least one must be given. A non-NULL buffer
 * whose capacity is below the size query's answer fails with DRAPE_ERROR_BUFFER_TOO_SMALL and
 * nothing is written. DRAPE_ERROR_CALL_ORDER before the first successful update for positions
 * and normals (indices are available at once). */
DRAPE_API drape_result DRAPE_CALL drape_context_read_body_mesh(drape_context* context,
                                                               drape_vec3* positions,
                                                               drape_vec3* normals,
                                                               uint32_t vertex_capacity,
                                                               uint32_t* indices,
                                                               uint32_t index_capacity);

/* ------------------------------------------------------------------------------------------ */
/* Tracking ellipsoids (proxies)                                                               */
/* ------------------------------------------------------------------------------------------ */

/* One tracking ellipsoid: world point p is inside when |diag(1/radii) * [axis_x axis_y axis_z]^T
 * (p - centre)| < 1. Axes are unit and orthogonal (a rotation); axis_y runs along the bone. With
 * the Drape rule the last five are fills (docs/proxies.md). First the pelvis fill: chain = the
 * torso, ring = its first (hip) ring, axis_y from between the thighs' first rings up to the hip
 * ring's centre; met by a template garment's torso cloth (not trousers') while both legs' hips and
 * knees are tracked, by no other cloth. Then the shoulder fills (right, then
 * left): chain = the arm, ring = its junction ring, axis_y from the base of the neck to the
 * shoulder joint; cloth of the torso collides with them too. Then the hip fills (right, then
 * left): chain = the leg, ring = its first (thigh) ring, axis_y from the thigh ring up to the hip
 * ring's side; cloth of that leg collides with them, and a template garment's torso cloth on that
 * side while the leg's hip and knee are tracked. */
typedef struct drape_ellipsoid {
  drape_vec3 centre;
  drape_vec3 axis_x;  /* body forward (limbs: carried along the limb without twist) */
  drape_vec3 axis_y;  /* along the bone */
  drape_vec3 axis_z;  /* axis_x x axis_y */
  drape_vec3 radii;   /* semi-axes along axis_x, axis_y, axis_z, metres */
  int32_t chain;      /* 0 torso, 1 neck and head, 2 left arm, 3 right arm, 4 left leg, 5 right leg */
  int32_t ring;       /* index of the feature ring it was built from */
} drape_ellipsoid;

/* Number of tracking ellipsoids (fixed for a context: depends on the rule and the ring layout). */
DRAPE_API drape_result DRAPE_CALL drape_context_get_ellipsoid_count(drape_context* context,
                                                                    uint32_t* out_count);

/* Copies the ellipsoids of the last update (capacity >= count). out_count may be NULL.
 * DRAPE_ERROR_CALL_ORDER before the first update. */
DRAPE_API drape_result DRAPE_CALL drape_context_read_ellipsoids(drape_context* context,
                                                                drape_ellipsoid* ellipsoids,
                                                                uint32_t capacity,
                                                                uint32_t* out_count);

/* Same as 4x4 column-major matrices M = T * R * S (unit sphere -> ellipsoid), 16 floats each, for
 * debug drawing a unit sphere mesh. capacity counts matrices. */
DRAPE_API drape_result DRAPE_CALL drape_context_read_ellipsoid_matrices(drape_context* context,
                                                                        float* matrices,
                                                                        uint32_t capacity,
                                                                        uint32_t* out_count);

/* How closely the ellipsoids follow the body mesh of the last update (docs/proxies.md):
 * body -> proxies is each body vertex's distance outside the union of ellipsoids (0 inside);
 * proxies -> body is how far points on the union's surface lie outside the body (0 inside). */
typedef struct drape_proxy_fidelity {
  uint32_t struct_size;          /* caller sets sizeof(drape_proxy_fidelity) */
  uint32_t union_samples;        /* surface points of the union measured */
  float body_to_proxy_mean_mm, body_to_proxy_p95_mm, body_to_proxy_max_mm;
  float proxy_to_body_mean_mm, proxy_to_body_p95_mm, proxy_to_body_max_mm;
  float outside_fraction;        /* body vertices outside every ellipsoid by more than 0.5 mm */
  float reserved;
} drape_proxy_fidelity;

/* Measures the fidelity now (about a millisecond: it is a diagnostic, not a per-frame stage).
 * DRAPE_ERROR_CALL_ORDER before the first update. */
DRAPE_API drape_result DRAPE_CALL drape_context_measure_proxy_fidelity(drape_context* context,
                                                                       drape_proxy_fidelity* out);

/* ------------------------------------------------------------------------------------------ */
/* Statistics                                                                                  */
/* ------------------------------------------------------------------------------------------ */

typedef struct drape_frame_stats {
  uint32_t struct_size;       /* caller sets sizeof(drape_frame_stats) */
  uint32_t frames_pushed;     /* push calls (accepted + rejected) */
  uint32_t frames_accepted;
  uint32_t frames_rejected;
  uint32_t frames_dropped;    /* accepted but replaced before an update consumed them */
  uint32_t updates;           /* updates that consumed a new frame */
  uint32_t teleports;         /* teleports detected so far */
  uint8_t teleported;         /* 1 if the last update's frame was a teleport */
  uint8_t calibrated;         /* 1 once bone lengths are frozen */
  uint8_t pose_jumped;        /* 1 if the last update's frame was a pose jump: the torso, or a
                                 limb bone with both joints tracked, turned farther than a person
                                 can in the frame time (a skeleton flipped upside down, thighs
                                 reported pointing up); filters restarted, garments re-placed and
                                 put back when the pose returns */
  uint8_t reserved1;
  double last_timestamp_s;    /* of the last accepted frame */
  double skeleton_ms;         /* wall time of the last update's skeleton stage */
  double body_ms;             /* wall time of the last update's ring + mesh stage */
  double proxies_ms;          /* wall time of the last update's tracking-ellipsoid stage */
  float body_volume_l;        /* enclosed volume of the body mesh after the last update */
  uint32_t pose_jumps;        /* pose jumps detected so far (docs/skeleton.md, "Pose jumps") */
} drape_frame_stats;

DRAPE_API drape_result DRAPE_CALL drape_context_get_frame_stats(drape_context* context,
                                                                drape_frame_stats* out_stats);

/* ------------------------------------------------------------------------------------------ */
/* Garments                                                                                    */
/* ------------------------------------------------------------------------------------------ */

/* A garment worn by the context's person: a cloth simulated against the tracking ellipsoids,
 * attached to the body's rings (waistband, collar). Owned by its context: destroyed with it, or
 * earlier with drape_garment_destroy. Method: docs/garments.md. */
typedef struct drape_garment drape_garment;

typedef enum drape_garment_kind {
  DRAPE_GARMENT_TSHIRT = 0,
  DRAPE_GARMENT_LONG_SLEEVE = 1,
  DRAPE_GARMENT_SKIRT = 2,
  DRAPE_GARMENT_DRESS = 3,
  DRAPE_GARMENT_TROUSERS = 4,
  DRAPE_GARMENT_KIND_FORCE32 = 0x7fffffff
} drape_garment_kind;

typedef enum drape_solver {
  DRAPE_SOLVER_XPBD = 0,        /* substepped XPBD, one iteration per substep (default) */
  DRAPE_SOLVER_MASS_SPRING = 1, /* the paper's mass-spring + explicit Euler (needs ~3 kHz) */
  DRAPE_SOLVER_FORCE32 = 0x7fffffff
} drape_solver;

typedef enum drape_contact_response {
  DRAPE_CONTACT_RADIAL = 0, /* the paper: project along the ray from the ellipsoid's centre */
  DRAPE_CONTACT_EXACT = 1,  /* closest point on the ellipsoid (default) */
  DRAPE_CONTACT_FORCE32 = 0x7fffffff
} drape_contact_response;

/* What proportions one garment is cut for (drape_garment_desc.cut): the context's choice
 * (drape_context_desc.garment_fit) or its own, so that one person can wear a top cut for the body
 * shape and trousers cut for their skeleton (docs/garments.md, "One garment's cut" and "Cut by
 * kind"). drape_garment_stats.cut says what a garment got. */
typedef enum drape_garment_cut {
  DRAPE_GARMENT_CUT_CONTEXT = 0,  /* as drape_context_desc.garment_fit says (a zero-filled desc) */
  DRAPE_GARMENT_CUT_SHAPE = 1,    /* as DRAPE_GARMENT_FIT_SHAPE, whatever the context's choice */
  DRAPE_GARMENT_CUT_SKELETON = 2, /* as DRAPE_GARMENT_FIT_SKELETON, whatever the context's choice */
  /* Trousers and long-sleeve templates as DRAPE_GARMENT_CUT_SKELETON, every other garment (T-shirt,
   * skirt and dress templates, OBJ and mesh garments) as DRAPE_GARMENT_CUT_CONTEXT. Why: legs and
   * sleeves that reach the ankles and wrists stay round the person's limbs only when cut to the
   * person's limb lengths (on the shared Kinect takes the shape's trousers hang past the feet in
   * every frame, on the CMU takes the long sleeves past the hands), while the shorter garments keep
   * less stretch on the shape's cut. Except: when the tracked bones say the body shape is too small
   * for the person (their median length over 1.25 x 0.85 times the shape's standard proportions:
   * trackers read bones ~15 % short, so e.g. an adult on a 1.0-1.3 m shape), the T-shirt, skirt and
   * dress templates are cut for the skeleton too, and every garment cut for the skeleton is cut for
   * the bones of the first pose at once (before its first step if it has not stepped yet), then again
   * at the calibration; a shape change decides again (a shape that fits takes them back to the
   * shape's cut). Cut for a 1.0 m shape, a dress on an adult stretched to three times its length
   * (docs/garments.md, "A shape too small for the person"). Default (drape_garment_desc_init). */
  DRAPE_GARMENT_CUT_BY_KIND = 3,
  DRAPE_GARMENT_CUT_FORCE32 = 0x7fffffff
} drape_garment_cut;

/* How a garment is built, fixed for its life. */
typedef struct drape_garment_desc {
  uint32_t struct_size;   /* sizeof(drape_garment_desc), set by drape_garment_desc_init */
  int32_t solver;         /* drape_solver; default DRAPE_SOLVER_XPBD */
  float area_density;     /* kg/m^2, (0, 10]; 0.2 (a light cotton shirt) */
  uint32_t max_tethers;   /* long-range attachments per particle, [0, 8]; 2 */
  float dress_time_s;     /* settling on the rest pose when added, [0, 10]; 0.5 */
  int32_t cut;            /* drape_garment_cut; default DRAPE_GARMENT_CUT_BY_KIND (the field was
                             `reserved` before: a zero-filled desc gets DRAPE_GARMENT_CUT_CONTEXT) */
} drape_garment_desc;

DRAPE_API drape_result DRAPE_CALL drape_garment_desc_init(drape_garment_desc* desc);

/* A procedural garment sized to the context's body shape (docs/cloth-solver.md). */
typedef struct drape_garment_template {
  uint32_t struct_size;  /* sizeof(drape_garment_template), set by drape_garment_template_init */
  int32_t kind;          /* drape_garment_kind; default DRAPE_GARMENT_TSHIRT */
  uint32_t particles;    /* target particle count, [200, 200000]; 2000. The result is
                            within -5 / +2.5 % from 1000 up, 10 % below. Coarser than about
                            500 (long sleeve, trousers, dress, skirt) or 300 (T-shirt), limbs
                            leave their tubes on the shared takes (docs/cloth-solver.md,
                            "Coarse garments come off") */
  float ease_m;          /* clearance over the body, [0.002, 0.1]; 0.025 (a long sleeve: 2 cm more
                            at the armhole, tapering to 0.6 of it at the cuff) */
  float length_scale;    /* hem / sleeve / leg lengths, [0.5, 1.5]; 1 */
  uint32_t reserved;     /* must be 0 */
} drape_garment_template;

DRAPE_API drape_result DRAPE_CALL drape_garment_template_init(drape_garment_template* tmpl);

/* Cloth parameters; may change at any time with drape_garment_set_params. */
typedef struct drape_cloth_params {
  uint32_t struct_size;        /* sizeof(drape_cloth_params), set by drape_cloth_params_init */
  float substep_hz;            /* substeps per simulated second, [30, 20000]; 300 */
  uint32_t max_substeps;       /* per step, [1, 1000]; 200 (longer steps get longer substeps) */
  float max_step_s;            /* a longer dt simulates only this much cloth time, [1e-4, 1]; 0.1 */
  drape_vec3 gravity;          /* m/s^2, |g| <= 1000; (0, -9.81, 0) */
  drape_vec3 wind;             /* m/s, |w| <= 1000; 0 */
  float drag;                  /* 1/s, pulls velocity towards the wind, [0, 1000]; 0 */
  float damping;               /* 1/s, [0, 1000]; 1 */
  float max_speed;             /* m/s speed clamp, [0, 1000], 0 = none; 20 */
  float stretch_compliance;    /* XPBD compliance (m/N), [0, 1]; 0 (inextensible) */
  float shear_compliance;      /* [0, 1]; 1e-6 */
  float bend_compliance;       /* [0, 1]; 1e-3 */
  float tether_compliance;     /* [0, 1]; 0 */
  float tether_scale;          /* a particle stays within rest * scale of its anchor, [1, 10]; 1.1 */
  float static_friction;       /* [0, 10]; 0.6 */
  float kinetic_friction;      /* [0, 10]; 0.4 */
  float collision_margin_m;    /* gap kept outside the ellipsoids (cloth thickness), [0, 0.05]; 0.004 */
  int32_t contact_response;    /* drape_contact_response; DRAPE_CONTACT_EXACT */
  uint32_t continuous_collision; /* 0 or 1: swept test across each substep; 1 */
  float linear_inertia;        /* [0, 1]: 1 physical, 0 carried rigidly with the pelvis; 0.5 */
  float angular_inertia;       /* [0, 1]; 0.5 */
  float blend_in_s;            /* first frame and teleports: the new pose is blended in over this
                                  much simulated time, [0, 2]; 0.3 (on the first frame after the
                                  garment is carried into the pose from its rest pose: up to 1 s
                                  more, docs/garments.md) */
  float spring_stretch;        /* mass-spring solver only: N/m, [0, 1e6]; 100 */
  float spring_shear;          /* N/m; 20 */
  float spring_bend;           /* N/m; 2 */
  float spring_damping;        /* N s/m along each spring; 0.01 */
  uint32_t iterations;         /* XPBD constraint passes per substep, [1, 64]; 1 (the method: more
                                  substeps beat more passes; drape-bench prices both). 2 with
                                  strain_limit 0.07 in 8 passes: a T-shirt's P99 stretch 13.2 ->
                                  11.7 % and its worst frame's depth 6.4 -> 4.1 mm on the default
                                  scene for about 30 % more frame time, but long sleeves come off
                                  a waving arm (docs/benchmarks.md, "Each setting against Bullet
                                  from its own shirt"). The mass-spring solver has no passes and
                                  ignores it */
  float strain_limit;          /* XPBD: at the end of every step the structural edges longer than
                                  rest * (1 + strain_limit) are pulled back to that length
                                  (strain_limit_passes passes, before the last collision), [0, 10],
                                  0 = off; 0.1.
                                  Takes the place of a `reserved` field that had to be 0, so
                                  older callers keep their behaviour (off). The mass-spring
                                  solver ignores it */
  /* The last field came after the rest: params whose struct_size is DRAPE_CLOTH_PARAMS_SIZE_V1
   * (128, the layout without it) are accepted and get its default. */
  uint32_t collision_stride;   /* XPBD: collide with the ellipsoids every Nth substep (the swept
                                  test spans the N substeps), [0, 8]; 0 (default): by the garment's
                                  resolution, every substep for 300 to 1 250 particles (coarse
                                  sleeves and trouser legs otherwise come off the limbs) and every
                                  second one outside (docs/garments.md, "Coarse garments collide
                                  every substep"). 1 costs about twice the collision time of 2. The
                                  mass-spring solver collides every substep and ignores it */
  /* Appended after collision_stride: params whose struct_size is DRAPE_CLOTH_PARAMS_SIZE_V2 (132,
   * the layout without it) or V1 are accepted and get its default. */
  uint32_t strain_limit_passes; /* XPBD: Gauss-Seidel passes of the strain limit at the end of each
                                  step, [1, 16]; 2. Each pass over the structural edges costs about
                                  4 us at 2 000 particles here; with a tighter strain_limit, more
                                  passes buy less stretch: 8 passes at 0.05 lowered the P99
                                  stretch of 4 of the 5 templates by 15-18 % over the shared takes,
                                  for about 6 % more frame time, but took a long sleeve off a waving
                                  arm (docs/garments.md, "More strain-limit passes"). Ignored when
                                  strain_limit is 0 and by the mass-spring solver */
} drape_cloth_params;

/* sizeof(drape_cloth_params) before collision_stride. */
#define DRAPE_CLOTH_PARAMS_SIZE_V1 128u
/* sizeof(drape_cloth_params) before strain_limit_passes. */
#define DRAPE_CLOTH_PARAMS_SIZE_V2 132u

/* Fills the first `struct_size` bytes of `params` with the defaults and sets params->struct_size to
 * it; nothing past them is written. struct_size from DRAPE_CLOTH_PARAMS_SIZE_V1 to this library's
 * sizeof(drape_cloth_params); outside: DRAPE_ERROR_INVALID_ARGUMENT (a size above it is a header
 * newer than the library) and nothing written. Call it through drape_cloth_params_init below. */
DRAPE_API drape_result DRAPE_CALL drape_cloth_params_init_sized(drape_cloth_params* params, uint32_t struct_size);
/* The exported drape_cloth_params_init fills the first layout only (DRAPE_CLOTH_PARAMS_SIZE_V1 bytes,
 * struct_size 128): a host built before collision_stride calls it with a 128-byte struct, which the
 * library's larger struct must not overrun. Code built with this header calls the sized init with
 * its own sizeof instead, through the inline function and macro below. */
DRAPE_API drape_result DRAPE_CALL drape_cloth_params_init(drape_cloth_params* params);
static inline drape_result drape_cloth_params_init_current(drape_cloth_params* params) {
  return drape_cloth_params_init_sized(params, (uint32_t)sizeof(drape_cloth_params));
}
#define drape_cloth_params_init drape_cloth_params_init_current

/* Adds a template garment, dressed on the body's rest pose (~ms per 1 000 particles). desc and
 * cloth may be NULL for defaults. On success *out_garment is a new handle owned by the context.
 * Thread-safety: one thread per context. */
DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_template(drape_context* context,
                                                                     const drape_garment_desc* desc,
                                                                     const drape_garment_template* tmpl,
                                                                     const drape_cloth_params* cloth,
                                                                     drape_garment** out_garment);

typedef enum drape_mesh_facing {
  DRAPE_MESH_FACING_PLUS_Z = 0,  /* the character faces +Z (MakeHuman, Blender's glTF export) */
  DRAPE_MESH_FACING_MINUS_Z = 1, /* faces -Z, subject's right at +X: Drape's own frame */
  DRAPE_MESH_FACING_FORCE32 = 0x7fffffff
} drape_mesh_facing;

/* How a garment mesh made for another body is placed on this one (docs/garment-obj.md). The
 * defaults fit MakeHuman garments (decimetres, facing +Z, A-pose, 1.60 m / 46.3 kg base mesh). */
typedef struct drape_mesh_fit {
  uint32_t struct_size;        /* sizeof(drape_mesh_fit), set by drape_mesh_fit_init */
  float unit_scale;            /* metres per mesh unit, [0, 1000]; 0 = detect (1, 0.1, 0.01, 0.001) */
  int32_t facing;              /* drape_mesh_facing; DRAPE_MESH_FACING_PLUS_Z */
  float source_height_m;       /* the body the mesh was made for, [0.8, 2.5]; 1.60 */
  float source_weight_kg;      /* [15, 300]; 46.3 (docs/garment-obj.md) */
  float source_floor_y_m;      /* where that body's feet are, after scaling, [-100, 100]; -0.82 */
  float source_axis_z_m;       /* z of that body's vertical axis, after scaling, [-100, 100]; 0.05 */
  float source_arm_down_deg;   /* its upper arms below horizontal, [0, 90]; 50 */
  float source_elbow_flex_deg; /* its elbows bent forward, [0, 150]; 45 */
  float source_leg_spread_deg; /* its legs turned outward, [0, 45]; 6 */
  float blend_m;               /* soft choice of the body segment a vertex follows, [0, 0.2]; 0.015 */
  uint32_t reserved;           /* must be 0 */
} drape_mesh_fit;

DRAPE_API drape_result DRAPE_CALL drape_mesh_fit_init(drape_mesh_fit* fit);

/* Adds a garment from a Wavefront OBJ file (UTF-8 path) or OBJ text in memory (copied): faces of
 * 3+ vertices, split into triangles; retargeted onto the body's rings and attached at its top
 * boundary loops (docs/garment-obj.md); a garment with no such loop (a patch, a decoration) is
 * added unattached and rests on the body by collision (drape_garment_stats.attached tells). fit,
 * desc and cloth may be NULL for defaults. */
DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_obj_file(drape_context* context,
                                                                     const char* path,
                                                                     const drape_mesh_fit* fit,
                                                                     const drape_garment_desc* desc,
                                                                     const drape_cloth_params* cloth,
                                                                     drape_garment** out_garment);
DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_obj_memory(drape_context* context,
                                                                       const void* data, size_t size,
                                                                       const drape_mesh_fit* fit,
                                                                       const drape_garment_desc* desc,
                                                                       const drape_cloth_params* cloth,
                                                                       drape_garment** out_garment);
/* The same from a triangle mesh in caller arrays (copied): vertex_count positions in the mesh's
 * units, index_count (a multiple of 3) indices, counter-clockwise seen from outside. */
DRAPE_API drape_result DRAPE_CALL drape_context_add_garment_mesh(drape_context* context,
                                                                 const drape_vec3* positions,
                                                                 uint32_t vertex_count,
                                                                 const uint32_t* indices,
                                                                 uint32_t index_count,
                                                                 const drape_mesh_fit* fit,
                                                                 const drape_garment_desc* desc,
                                                                 const drape_cloth_params* cloth,
                                                                 drape_garment** out_garment);

/* Removes the garment from its context and frees it; views into it become invalid. NULL is
 * accepted and ignored. */
DRAPE_API drape_result DRAPE_CALL drape_garment_destroy(drape_garment* garment);

/* Replaces the cloth parameters (validated as a whole; on failure nothing changes). Calls on a
 * garment count as calls on its context (one thread per context). */
DRAPE_API drape_result DRAPE_CALL drape_garment_set_params(drape_garment* garment,
                                                           const drape_cloth_params* params);
/* `out_params->struct_size` must be set by the caller (drape_cloth_params_init does). */
DRAPE_API drape_result DRAPE_CALL drape_garment_get_params(drape_garment* garment,
                                                           drape_cloth_params* out_params);

/* Layered garments (docs/garments.md, "Layered garments"). A garment of layer L >= 2 is worn over
 * every garment of its context whose layer is 1 .. L - 1 (a T-shirt over trousers: trousers 1,
 * T-shirt 2): it collides with the body's ellipsoids each grown by how far the cloth under it
 * stands off that ellipsoid, measured every step from where that cloth lies (cloth up to 3 cm off
 * the body counts; farther, a flare or a loose fold, does not), so it lies on that cloth instead
 * of passing through it. The cloth under is not moved by the cloth over it. 0, the default, is not
 * layered: the garment meets the body alone and nothing lies on it (a garment of layer 1 is under
 * the others and meets the body alone too). layer in [0, 255]: outside it
 * DRAPE_ERROR_OUT_OF_RANGE, nothing changed. A new layer wakes every garment of the context
 * (drape_pipeline_options.sleep). The offsets grow by at most 1 cm a step (the garment over moves
 * out like a body part, 0.3 m/s at 30 Hz) and shrink by at most 2 mm a step. */
DRAPE_API drape_result DRAPE_CALL drape_garment_set_layer(drape_garment* garment, int32_t layer);
DRAPE_API drape_result DRAPE_CALL drape_garment_get_layer(drape_garment* garment, int32_t* out_layer);

/* Advances the world by dt seconds (the host's frame time; it may vary from frame to frame): runs
 * drape_context_update if a frame is queued, then every garment follows the body from where it
 * was at the last step to where it is now, in ceil(dt * substep_hz) substeps. dt in (0, 10];
 * the cloth simulates dt clamped to [1e-5, max_step_s] (a shorter step is no time to simulate).
 * DRAPE_ERROR_CALL_ORDER before the first accepted frame. Thread-safety: one thread per context. */
DRAPE_API drape_result DRAPE_CALL drape_context_step(drape_context* context, float dt);

/* Vertex and index counts of the garment mesh (fixed for the garment). Either out may be NULL. */
DRAPE_API drape_result DRAPE_CALL drape_garment_get_mesh_size(drape_garment* garment,
                                                              uint32_t* out_vertex_count,
                                                              uint32_t* out_index_count);

/* Copies the current garment mesh, as drape_context_read_body_mesh does for the body: each of
 * positions, normals (vertex_capacity) and indices (index_capacity) may be NULL, not all three.
 * Normals are computed on request (area-weighted, unit). */
DRAPE_API drape_result DRAPE_CALL drape_garment_read_mesh(drape_garment* garment,
                                                          drape_vec3* positions,
                                                          drape_vec3* normals,
                                                          uint32_t vertex_capacity,
                                                          uint32_t* indices,
                                                          uint32_t index_capacity);

/* The garment's rest shape (the cut: every edge at its rest length), vertex_capacity >= the
 * vertex count, in the same order as drape_garment_read_mesh. For measuring stretch. */
DRAPE_API drape_result DRAPE_CALL drape_garment_read_rest_positions(drape_garment* garment,
                                                                    drape_vec3* positions,
                                                                    uint32_t vertex_capacity);

/* Borrowed view of the particle positions, no copy: *out_xyzw points at vertex_count float4
 * (x, y, z in metres, w = inverse mass, 0 for attached particles), owned by the library and valid
 * until the next drape_context_step, drape_context_set_body_shape, drape_garment_set_params,
 * drape_garment_destroy or drape_context_destroy. Read-only. */
DRAPE_API drape_result DRAPE_CALL drape_garment_view_positions(drape_garment* garment,
                                                               const float** out_xyzw,
                                                               uint32_t* out_vertex_count);

/* What the last step did. struct_size 72 (the first version, without the device_* fields) is
 * still accepted: then only its first 72 bytes are written. */
typedef struct drape_garment_stats {
  uint32_t struct_size;     /* caller sets sizeof(drape_garment_stats); the library writes back
                               how many bytes it filled */
  uint32_t particles;
  uint32_t attached;        /* particles pinned to body rings */
  uint32_t substeps;        /* in the last step (blend-in frames included) */
  uint32_t blend_frames;    /* extra 1/30 s frames the last step ran to blend a new pose in */
  uint32_t contacts;        /* particle-ellipsoid corrections in the last step */
  uint32_t swept_catches;   /* of which caught by the swept test */
  uint32_t escapes;         /* particles squeezed between overlapping ellipsoids */
  uint64_t steps;           /* steps so far */
  uint8_t teleport_reset;   /* 1 if the last step carried the garment across a teleport */
  uint8_t nan_reset;        /* 1 if the last step had to restore the garment (please report) */
  uint8_t cut;              /* what the garment is cut for, its desc's cut resolved: a
                               drape_garment_fit (DRAPE_GARMENT_FIT_SKELETON: recut for the person
                               once the tracker calibrates) */
  uint8_t reserved1;
  uint32_t refits;          /* times the garment was cut again (a body shape change, the skeleton's
                               calibration: drape_garment_fit); its rest shape
                               (drape_garment_read_rest_positions) changes then, nothing else */
  double step_ms;           /* wall time of the garment's last step (its own: on the CPU the
                               other garments stepped in the same drape_context_step are not in it;
                               a device frame run in a batched launch counts the whole launch) */
  double collide_ms;        /* of which ellipsoid collision; 0 on the OpenCL backend, where
                               collision runs inside the device frame (docs/opencl.md) */
  double integrate_ms;      /* the rest: integration and constraints; on OpenCL the whole
                               device frame (its transfers and the wait for it included) */
  /* OpenCL backend: where the last step's device frames went, from the queue's profiling events
   * (summed over the step's frames). What integrate_ms holds beyond their sum is the host
   * enqueueing the launches and waiting for them. 0 on the CPU backend, and when the frame ran
   * batched with other garments' (drape_step_contexts, or several device garments in one
   * context): a batch is timed as a whole, not per garment (docs/opencl.md). */
  double device_upload_ms;   /* host -> device writes: the garment record, pins, ellipsoids */
  double device_kernel_ms;   /* the first launch's start to the last one's end */
  double device_readback_ms; /* positions (and normals when read) back to the host */
  double device_host_ms;     /* the host packing the frame (collision spans) before the uploads */
} drape_garment_stats;

DRAPE_API drape_result DRAPE_CALL drape_garment_get_stats(drape_garment* garment,
                                                          drape_garment_stats* out_stats);

/* Accuracy of the garment now (a diagnostic, ~0.6 ms per 1 000 particles). The struct grew from
 * 32 to 40 bytes (openings) and to 44 (inside_body); a caller passing an earlier version's
 * struct_size (32 or 40) gets those fields as before and nothing written past them. */
typedef struct drape_garment_accuracy {
  uint32_t struct_size;            /* caller sets sizeof(drape_garment_accuracy) */
  uint32_t proxy_inside;           /* particles inside an ellipsoid they collide with, > 0.1 mm */
  float max_stretch;               /* structural edges: max of |len| / rest - 1 */
  float p99_stretch;               /* its 99th percentile */
  float mean_stretch;
  float body_penetration_p99_mm;   /* depth of vertices inside the body mesh (0 before an update);
                                      inside = winding number >= 1, depth = distance to the mesh */
  float body_penetration_max_mm;
  float deeper_than_2mm;           /* fraction of vertices more than 2 mm inside the body */
  /* Openings: the mesh's boundary loops (hem, collar, sleeve cuffs, trouser legs) that went
   * round a body part when the garment was dressed (a sleeve round its arm, a collar round the
   * spine); openings_off: how many of them are off it now (a sleeve the arm has left, a trouser
   * leg the foot came out of through the cloth). docs/garments.md, "Openings". */
  uint32_t openings;
  uint32_t openings_off;
  float inside_body;               /* fraction of vertices inside the body mesh at any depth (winding
                                      number >= 1): how ../shared/ANCHORS.md counts "cloth inside the
                                      body" (NvCloth 0.40 %). 0 before an update */
} drape_garment_accuracy;

DRAPE_API drape_result DRAPE_CALL drape_garment_measure(drape_garment* garment,
                                                        drape_garment_accuracy* out_accuracy);

/* ------------------------------------------------------------------------------------------ */
/* Adaptive pipeline                                                                           */
/* ------------------------------------------------------------------------------------------ */

/* What a context skips when the scene does not need it (docs/adaptive.md). All on by default;
 * what the host reads is the same either way, only when it is computed changes:
 *  - cull_proxies: only the tracking ellipsoids some awake garment can reach (from its attachments
 *    and the length of cloth hanging from them) are built each update, and each garment collides
 *    with its own. drape_context_read_ellipsoids, _read_ellipsoid_matrices, _measure_proxy_fidelity
 *    and drape_garment_measure build the rest for the current frame first.
 *  - stages_on_demand: the body mesh's positions and normals are computed when read
 *    (drape_context_read_body_mesh), measured (fidelity, garment accuracy) or needed by
 *    drape_context_get_frame_stats (body volume), not on every update (drape_frame_stats.body_ms
 *    then times the rings only). Off: every update computes them (a host that reads the mesh
 *    every frame gains nothing from laziness).
 *  - sleep: a garment whose particles have all moved slower than sleep_speed_m_s for
 *    sleep_delay_s while every joint stayed within sleep_distance_m of where it was skips its steps.
 *    It wakes, before anything is built for that frame, when a joint leaves that distance, on a
 *    teleport, a new body shape, new cloth parameters (drape_garment_set_params), new pipeline
 *    options or drape_context_wake; its first step sweeps the body from where it fell asleep, so
 *    it continues without a jump.
 * Choosing the cloth backend by garment size (CPU or OpenCL) is the backend's option, not this. */
typedef enum drape_pipeline_stage {
  DRAPE_STAGE_BODY_MESH = 1,     /* body vertex positions */
  DRAPE_STAGE_BODY_NORMALS = 2,  /* body vertex normals */
  DRAPE_STAGE_PROXIES = 4,       /* some tracking ellipsoids (culled) */
  DRAPE_STAGE_CLOTH = 8,         /* some garment's step (asleep) */
  DRAPE_STAGE_FORCE32 = 0x7fffffff
} drape_pipeline_stage;

typedef struct drape_pipeline_options {
  uint32_t struct_size;      /* sizeof(drape_pipeline_options), set by drape_pipeline_options_init */
  uint32_t cull_proxies;     /* 0 or 1; 1 */
  uint32_t stages_on_demand; /* 0 or 1; 1 */
  uint32_t sleep;            /* 0 or 1; 1 */
  float sleep_delay_s;       /* stillness before a garment sleeps, [0, 60]; 0.5 */
  float sleep_distance_m;    /* joints within this of where they were are still, [0, 1]; 0.005 */
  float sleep_speed_m_s;     /* particles slower than this are still, [0, 10]; 0.02 */
  float reach_margin_m;      /* added to each garment's reach (a frame of body motion), [0, 2]; 0.1 */
  uint32_t reserved;         /* must be 0 */
} drape_pipeline_options;

/* Fills `options` with the defaults (everything adaptive on) and struct_size. */
DRAPE_API drape_result DRAPE_CALL drape_pipeline_options_init(drape_pipeline_options* options);
/* Replaces the context's options (validated as a whole; on failure nothing changes). Wakes every
 * garment. Takes effect at the next update or step; turning stages_on_demand off computes the
 * current frame's mesh at once. */
DRAPE_API drape_result DRAPE_CALL drape_context_set_pipeline_options(drape_context* context,
                                                                     const drape_pipeline_options* options);
/* `out_options->struct_size` must be set by the caller (drape_pipeline_options_init does). */
DRAPE_API drape_result DRAPE_CALL drape_context_get_pipeline_options(drape_context* context,
                                                                     drape_pipeline_options* out_options);
/* Wakes every sleeping garment: the next step runs them all (e.g. after the host moved something
 * Drape does not see). */
DRAPE_API drape_result DRAPE_CALL drape_context_wake(drape_context* context);

/* What the adaptive pipeline skipped. "Frame": the last update (stages) or step (cloth). */
typedef struct drape_skip_stats {
  uint32_t struct_size;         /* caller sets sizeof(drape_skip_stats) */
  uint32_t proxies_available;   /* tracking ellipsoids the body has */
  uint32_t proxies_built;       /* of which the last update built (0 before the first update) */
  uint32_t stages_skipped_last; /* drape_pipeline_stage bits skipped in the last frame so far */
  uint32_t garments;            /* garments in the context */
  uint32_t garments_asleep;     /* of which asleep now */
  uint64_t updates;             /* updates that built the body for a new frame */
  uint64_t stages_skipped;      /* stage runs skipped so far (each bit of each frame counts 1) */
  uint64_t proxies_skipped;     /* ellipsoid builds skipped so far */
  uint64_t steps;               /* steps with at least one garment */
  uint64_t frames_slept;        /* of which steps in which every garment slept */
  uint64_t garment_steps_slept; /* garment steps skipped */
} drape_skip_stats;

DRAPE_API drape_result DRAPE_CALL drape_context_get_skip_stats(drape_context* context,
                                                               drape_skip_stats* out_stats);

/* ------------------------------------------------------------------------------------------ */
/* Recordings                                                                                  */
/* ------------------------------------------------------------------------------------------ */

typedef struct drape_recording drape_recording;

typedef enum drape_recording_format {
  DRAPE_RECORDING_UNKNOWN = 0,
  DRAPE_RECORDING_KINECT_CSV = 1, /* timestamp ticks + N x (x, y, z, state), as KinectReader */
  DRAPE_RECORDING_BVH = 2,        /* BVH, joints by forward kinematics, mapped to Kinect v2 */
  DRAPE_RECORDING_DRAPE = 3,      /* Drape's own text format (docs/recording-format.md) */
  DRAPE_RECORDING_FORCE32 = 0x7fffffff
} drape_recording_format;

typedef struct drape_recording_info {
  uint32_t struct_size;  /* caller sets sizeof(drape_recording_info) */
  int32_t format;        /* drape_recording_format, detected from the content */
  int32_t layout;        /* drape_layout of the frames */
  uint32_t joint_count;
  uint32_t frame_count;
  float nominal_rate_hz; /* median frame rate */
  double duration_s;
} drape_recording_info;

/* Reads a whole recording file. `path` is UTF-8 (on Windows, paths outside the ANSI code page are
 * not supported yet). layout: DRAPE_LAYOUT_AUTO, or the layout the file must have (an
 * error if it contradicts the content). On success the caller owns *out_recording and releases it
 * with drape_recording_destroy. Any thread. */
DRAPE_API drape_result DRAPE_CALL drape_recording_open(const char* path, int32_t layout,
                                                       drape_recording** out_recording);
/* Same from memory (the bytes are copied; the caller keeps ownership of `data`). */
DRAPE_API drape_result DRAPE_CALL drape_recording_open_memory(const void* data, size_t size,
                                                              int32_t layout,
                                                              drape_recording** out_recording);
/* NULL is accepted and ignored. One thread per recording. */
DRAPE_API drape_result DRAPE_CALL drape_recording_destroy(drape_recording* recording);
DRAPE_API drape_result DRAPE_CALL drape_recording_get_info(drape_recording* recording,
                                                           drape_recording_info* out_info);
/* Copies frame `index` (0-based) into joints (capacity >= joint_count). out_timestamp_s may be
 * NULL. Recording timestamps start at 0. */
DRAPE_API drape_result DRAPE_CALL drape_recording_read_frame(drape_recording* recording,
                                                             uint32_t index, drape_joint* joints,
                                                             uint32_t capacity,
                                                             double* out_timestamp_s);
/* Writes the recording in Drape's own format to `path`. */
DRAPE_API drape_result DRAPE_CALL drape_recording_save(drape_recording* recording,
                                                       const char* path);

/* ------------------------------------------------------------------------------------------ */
/* Backends                                                                                    */
/* ------------------------------------------------------------------------------------------ */
/* Where a context's garments run their cloth step (docs/opencl.md): the CPU, or an OpenCL 1.2
 * device (a GPU, or a CPU through PoCL) running the same XPBD step as kernels, the same answers
 * within float rounding. Only the XPBD solver has an OpenCL path (mass-spring stays on the CPU).
 * When OpenCL is asked for and no device works (no platform, bad index, the program does not
 * build, the device fails later), garments run on the CPU and drape_context_get_backend_info
 * says why: asking for OpenCL never makes a context unusable. */

typedef enum drape_backend {
  DRAPE_BACKEND_CPU = 0,     /* default */
  DRAPE_BACKEND_OPENCL = 1,  /* every XPBD garment on the chosen device */
  DRAPE_BACKEND_AUTO = 2,    /* OpenCL for garments of at least opencl_min_particles when a device works */
  DRAPE_BACKEND_FORCE32 = 0x7fffffff
} drape_backend;

typedef struct drape_backend_desc {
  uint32_t struct_size;            /* caller sets sizeof(drape_backend_desc) */
  int32_t backend;                 /* drape_backend; default DRAPE_BACKEND_CPU */
  int32_t platform_index;          /* OpenCL platform, -1 = choose (default); [-1, 255] */
  int32_t device_index;            /* device within the platform (or among all when the platform
                                      is -1), -1 = choose (default); [-1, 255] */
  uint32_t prefer_gpu;             /* when choosing: a GPU before other devices (default 1); 0 or 1 */
  uint32_t opencl_min_particles;   /* AUTO: smaller garments stay on the CPU (default 2000); [0, 1e8] */
  void* host_cl_context;           /* optional: the host's cl_context and cl_command_queue (both or */
  void* host_cl_queue;             /* neither); the indices are then ignored. Drape retains them. */
} drape_backend_desc;

DRAPE_API drape_result DRAPE_CALL drape_backend_desc_init(drape_backend_desc* desc);

/* Chooses the backend of every garment of the context, now and when added later. With OpenCL,
 * the device is chosen and the kernels are built here (PoCL: seconds; contexts asking for the same
 * device share one build). Garments keep their positions and velocities across the switch.
 * Returns DRAPE_OK when OpenCL was asked for but cannot run (see drape_backend_info). */
DRAPE_API drape_result DRAPE_CALL drape_context_set_backend(drape_context* context,
                                                            const drape_backend_desc* desc);

typedef struct drape_backend_info {
  uint32_t struct_size;            /* caller sets sizeof(drape_backend_info) */
  int32_t requested;               /* drape_backend last asked for */
  int32_t active;                  /* DRAPE_BACKEND_OPENCL when a device is in use, else CPU */
  uint32_t opencl_garments;        /* garments stepping on the device */
  uint32_t cpu_garments;           /* garments stepping on the CPU */
  uint32_t reserved;
  /* UTF-8, never NULL, owned by the context: valid until the next
   * drape_context_get_backend_info on this context or its destruction. */
  const char* device_name;         /* the OpenCL device in use ("" without one) */
  const char* platform_name;
  const char* fallback_reason;     /* why OpenCL was asked for and is not (fully) used, else "" */
} drape_backend_info;

DRAPE_API drape_result DRAPE_CALL drape_context_get_backend_info(drape_context* context,
                                                                 drape_backend_info* out_info);

/* OpenCL devices on this machine, in enumeration order (platform by platform). */
typedef struct drape_opencl_device {
  uint32_t struct_size;            /* caller sets sizeof(drape_opencl_device) */
  int32_t platform_index;
  int32_t device_index;
  uint32_t is_gpu;
  uint64_t global_mem_bytes;
  uint64_t local_mem_bytes;
  uint32_t compute_units;
  uint32_t reserved;
  const char* platform_name;       /* UTF-8, owned by the library, valid until the process ends */
  const char* device_name;
} drape_opencl_device;

/* Steps several contexts (people) by dt together: the same as drape_context_step on each in
 * order, with the same results bit for bit, but the OpenCL garments of every context that use
 * one device run their frame in the same launches (one batched launch for the garments small
 * enough for one work-group; docs/opencl.md, "Batching"), so N people cost about the launches
 * and transfers of one. contexts: count distinct live contexts, count in [1, 64]; dt as
 * drape_context_step. Every argument and every context's call order is checked before any
 * context steps: a rejected call changes nothing. Thread-safety: the calling thread must be the
 * only one using these contexts during the call. */
#define DRAPE_MAX_STEP_CONTEXTS 64
DRAPE_API drape_result DRAPE_CALL drape_step_contexts(drape_context* const* contexts, uint32_t count,
                                                      float dt);

/* Number of OpenCL devices: 0 (DRAPE_OK) without an OpenCL driver or in a build without OpenCL. */
DRAPE_API drape_result DRAPE_CALL drape_opencl_device_count(uint32_t* out_count);
DRAPE_API drape_result DRAPE_CALL drape_opencl_device_get(uint32_t index, drape_opencl_device* out_device);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* DRAPE_H */
