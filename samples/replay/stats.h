// drape-replay statistics: what the replay measured, the stats JSON (a stable contract, see
// docs/replay.md) and the stdout summary.
#pragma once

#include <drape/drape.h>

#include "layering.h"
#include "stretch.h"

#include <cstdint>
#include <string>
#include <vector>

namespace replay {

// The pictures (--render-every, --camera, --size; pictures.h).
struct RenderStats {
  bool png_available = false;      // built with stb_image_write
  uint32_t every = 0;              // 0: no pictures
  std::string camera = "both";
  uint32_t width = 0, height = 0;  // one view
  std::string dir;                 // where render_NNNNN.png go
  uint32_t frames_rendered = 0;    // render_NNNNN.png written
  std::vector<double> ms;          // per rendered picture (rasterise + compose, no file writing)
  std::string contact_sheet, gif, mp4;  // paths; empty: not written (JSON null)
  std::string mp4_note;            // why there is no MP4 ("ffmpeg not on PATH", ...)
};

struct ReplayStats {
  std::string drape_version;
  std::string recording;
  int32_t format = DRAPE_RECORDING_UNKNOWN;
  int32_t layout = DRAPE_LAYOUT_AUTO;
  uint32_t recording_frames = 0;  // frames in the file (summary only)
  float recording_rate_hz = 0.0f;

  uint32_t frames = 0;            // frames replayed (read from the recording and pushed)
  uint32_t rejected_frames = 0;   // pushes the library rejected
  uint32_t teleports = 0;         // drape_frame_stats.teleports after the last frame
  uint32_t pose_jumps = 0;        // drape_frame_stats.pose_jumps after the last frame
  uint64_t nonfinite = 0;         // NaN/Inf numbers in the library's outputs
  uint32_t vertices = 0;
  uint32_t triangles = 0;
  uint32_t watertight_frames = 0;
  uint32_t ring_points = 0;
  drape_body_shape shape{};       // resolved (drape_context_get_body_shape)

  // Per updated frame (rejected frames add nothing).
  std::vector<double> ms_per_frame;  // push + update wall time
  std::vector<double> skeleton_ms;
  std::vector<double> body_ms;
  std::vector<double> volume_l;
  std::vector<double> proxies_ms;

  // Tracking ellipsoids: count, rule, and fidelity on the measured frames (mm).
  uint32_t proxy_count = 0;
  int32_t proxy_rule = DRAPE_PROXY_RULE_DRAPE;
  double arm_clearance_m = -1.0;   // the context's arm_torso_clearance_m; < 0: arms_clear_torso off
  std::vector<double> body_to_proxy_p95, proxy_to_body_p95, fit_max, outside_fraction;

  // The garment (has_garment false: --garment none, every key below stays empty/0).
  bool has_garment = false;
  std::string garment_kind;        // template name or the OBJ path
  bool garment_from_obj = false;
  int32_t solver = DRAPE_SOLVER_XPBD;
  // Where the cloth ran (drape_context_get_backend_info after adding the garment): "cpu" or
  // "opencl", the OpenCL device's name ("" on the CPU) and why OpenCL was asked for and not used.
  std::string backend = "cpu", device, backend_fallback;
  double substep_hz = 0.0;         // drape_garment_get_params after adding
  uint32_t iterations = 0;         // the same: XPBD passes per substep
  double strain_limit = 0.0;       // the same: XPBD strain limit (0 = off)
  uint32_t strain_limit_passes = 0; // the same: its Gauss-Seidel passes
  uint32_t collision_stride = 0;   // the same: XPBD collision every N substeps (0 = by resolution)
  uint32_t particles = 0;          // garment vertex count
  uint32_t garment_triangles = 0;
  uint32_t attached = 0;
  uint32_t teleport_resets = 0;    // stepped frames with drape_garment_stats.teleport_reset
  uint32_t nan_resets = 0;         // ... with nan_reset
  int32_t garment_fit = DRAPE_GARMENT_FIT_SHAPE;  // the garment's cut (drape_garment_stats.cut)
  bool garment_fit_by_kind = false;               // chosen by its kind (--garment-fit by-kind)
  uint32_t refits = 0;             // drape_garment_stats.refits after the last step
  // Per stepped frame (drape_garment_get_stats after the step).
  std::vector<double> cloth_ms, integrate_ms, collide_ms, contacts, substeps;
  // OpenCL backend: the device frame's split (drape_garment_stats.device_*; 0 on the CPU).
  std::vector<double> device_upload_ms, device_kernel_ms, device_readback_ms, device_host_ms;
  // Stretch of every structural edge of every stepped frame, from the positions read back.
  StretchAccumulator stretch;
  // The body's own surface stretch under the garment: the body mesh's edges of the triangles
  // within kBodyUnderGarmentM of the garment on the first stepped frame from
  // body_stretch_from_frame (the context's calibration_frames: the bones calibrated), against
  // their length on that frame, every stepped frame from then on (what a garment that followed
  // the body's surface without sliding would stretch; docs/replay.md).
  static constexpr float kBodyUnderGarmentM = 0.04f;
  static constexpr float kBodyMinEdgeM = 0.002f;  // degenerate stitch triangles left out
  StretchAccumulator body_stretch;
  // The same edges but the stitches between tubes (vertex indices more than ring_points + 1
  // apart: the mesh stores its vertices ring by ring, docs/body-model.md), whose triangles bridge
  // the arm's and the torso's rings at the shoulders and stretch the most.
  StretchAccumulator body_tube_stretch;
  bool body_stretch_set = false;
  uint32_t body_stretch_from_frame = 0;
  // Per measured frame (drape_garment_measure, --measure-every).
  uint64_t proxy_inside = 0;       // summed over measured frames
  std::vector<double> penetration_p99_mm, penetration_max_mm, deeper_than_2mm, inside_body;
  // Openings (drape_garment_accuracy.openings): those round a body part when dressed, measured
  // frames with one or more off it, and the most off in one frame.
  uint32_t openings = 0, openings_off_frames = 0, openings_off_max = 0;
  // --under: the template garment worn under the garment (layer 1; the garment is layer 2), and on
  // every measured frame the share of the garment's vertices over it that lie under it instead.
  bool has_under = false;
  std::string under_kind;
  uint32_t under_particles = 0;
  LayerCrossing layer_crossing;

  RenderStats render;

  // The adaptive pipeline (drape_context_get_skip_stats; docs/adaptive.md).
  bool full_pipeline = false;        // --full-pipeline
  std::vector<double> proxies_built; // per updated frame, right after the update / step
  uint32_t proxies_available = 0;
  uint64_t stages_skipped = 0;       // after the last frame
  uint64_t frames_slept = 0;
};

// Median (mean of the two middle values for an even count) and nearest-rank percentile
// (p in [0, 100]); NaN for an empty sample, which the JSON writes as null.
double median(std::vector<double> v);
double percentile(std::vector<double> v, double p);
double maximum(const std::vector<double>& v);

const char* formatName(int32_t format);  // "kinect_csv", "bvh", "drape", "unknown"
const char* layoutName(int32_t layout);  // "kinect1", "kinect2", "azure", "auto"

// The stats JSON document.
std::string statsJson(const ReplayStats& s);

// The human-readable summary table printed to stdout.
std::string summaryText(const ReplayStats& s, const std::string& obj_dir, const std::string& stats_path);

}  // namespace replay
