// One CSV row per (setting, take): per-stage times (median and p90 over every steady frame of the
// timed repeats) and the error figures of the measuring run; writers for the CSVs.
#pragma once

#include "bullet_peer.h"
#include "energy.h"
#include "scenario.h"

#include <string>
#include <vector>

namespace bench {

struct StageTime {
  double median = 0, p90 = 0;
};

struct Row {
  Setting setting;
  std::string take;
  std::string device;  // OpenCL device and platform, when that backend ran
  double rate_hz = 0;
  uint32_t particles = 0;
  size_t timed_frames = 0;  // pooled over the repeats
  int repeats = 0;
  double substeps_per_frame = 0;
  StageTime frame, skeleton, body, proxies, cloth, integrate, collide;
  double ms_per_sim_s = 0;  // frame median x replay rate: run time per simulated second
  double dev_rms_mm = 0, dev_max_mm = 0;
  double stretch_p99 = 0, stretch_max = 0;
  double pen_p99_mm = 0, pen_max_mm = 0, deeper_than_2mm = 0, in_body = 0;
  double inside_mean = 0;
  uint32_t inside_max = 0;
  double openings_off = 0;  // fraction of measured frames with an opening off its body part
  EnergyDrift energy;
  uint32_t nan_resets = 0;
};

// Fills the time columns from the pooled frames of the timed runs.
void fillTimes(const std::vector<FrameTimes>& frames, double rate_hz, Row& row);

// Writes rows as CSV (header first). false + error on I/O failure.
bool writeRowsCsv(const std::string& path, const std::vector<Row>& rows, std::string& error);
bool writePeerCsv(const std::string& path, const std::vector<PeerResult>& peers, std::string& error);

}  // namespace bench
