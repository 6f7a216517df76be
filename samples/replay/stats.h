// drape-replay statistics: what the replay measured, the stats JSON (a stable contract, see
// docs/replay.md) and the stdout summary.
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <string>
#include <vector>

namespace replay {

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
  std::vector<double> body_to_proxy_p95, proxy_to_body_p95, fit_max, outside_fraction;
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
