#include "stats.h"

#include "json_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>

namespace replay {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The paper's reported body-stage time (rings + mesh per frame), shown for reference only: its
// hardware and mesh resolution differ from ours.
constexpr double kPaperBodyMs = 0.78;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void appendf(std::string& out, const char* fmt, ...) {
  char line[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  out += line;
}

std::string fmtMs(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return kNaN;
  const size_t n = v.size(), mid = n / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (n % 2 == 1) return upper;
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return kNaN;
  // Nearest rank: the smallest value with at least p % of the sample at or below it.
  size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  rank = std::min(std::max<size_t>(rank, 1), v.size());
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(rank - 1), v.end());
  return v[rank - 1];
}

double maximum(const std::vector<double>& v) {
  return v.empty() ? kNaN : *std::max_element(v.begin(), v.end());
}

const char* formatName(int32_t format) {
  switch (format) {
    case DRAPE_RECORDING_KINECT_CSV: return "kinect_csv";
    case DRAPE_RECORDING_BVH: return "bvh";
    case DRAPE_RECORDING_DRAPE: return "drape";
    default: return "unknown";
  }
}

const char* layoutName(int32_t layout) {
  switch (layout) {
    case DRAPE_LAYOUT_KINECT1: return "kinect1";
    case DRAPE_LAYOUT_KINECT2: return "kinect2";
    case DRAPE_LAYOUT_AZURE: return "azure";
    default: return "auto";
  }
}

std::string statsJson(const ReplayStats& s) {
  JsonWriter w;
  w.beginObject();
  w.key("drape_version").value(s.drape_version);
  w.key("recording").value(s.recording);
  w.key("format").value(formatName(s.format));
  w.key("layout").value(layoutName(s.layout));
  w.key("frames").value(s.frames);
  w.key("rejected_frames").value(s.rejected_frames);
  w.key("teleports").value(s.teleports);
  w.key("nonfinite").value(static_cast<int64_t>(s.nonfinite));

  w.key("ms_per_frame").beginObject();
  w.key("median").value(median(s.ms_per_frame));
  w.key("p90").value(percentile(s.ms_per_frame, 90.0));
  w.key("max").value(maximum(s.ms_per_frame));
  w.endObject();

  w.key("stages_ms").beginObject();
  w.key("skeleton").value(median(s.skeleton_ms));
  w.key("body").value(median(s.body_ms));
  w.key("proxies").value(median(s.proxies_ms));
  w.endObject();

  w.key("body").beginObject();
  w.key("vertices").value(s.vertices);
  w.key("triangles").value(s.triangles);
  w.key("watertight_frames").value(s.watertight_frames);
  w.key("volume_l").value(median(s.volume_l));
  w.endObject();

  // fit_p95_mm: per measured frame the larger of the two directions' P95 (body sticking out of
  // the ellipsoids, ellipsoids sticking out of the body), median over frames; fit_max_mm: the
  // largest single distance seen on any measured frame.
  std::vector<double> fit_p95;
  for (size_t i = 0; i < s.body_to_proxy_p95.size(); ++i)
    fit_p95.push_back(std::max(s.body_to_proxy_p95[i], s.proxy_to_body_p95[i]));
  w.key("proxies").beginObject();
  w.key("count").value(s.proxy_count);
  w.key("rule").value(s.proxy_rule == DRAPE_PROXY_RULE_PAPER ? "paper" : "drape");
  w.key("frames_measured").value(static_cast<uint32_t>(fit_p95.size()));
  w.key("fit_p95_mm").value(median(fit_p95));
  w.key("fit_max_mm").value(maximum(s.fit_max));
  w.key("body_to_proxy_p95_mm").value(median(s.body_to_proxy_p95));
  w.key("proxy_to_body_p95_mm").value(median(s.proxy_to_body_p95));
  w.key("outside_fraction").value(median(s.outside_fraction));
  w.endObject();

  w.key("shape").beginObject();
  w.key("height_m").value(static_cast<double>(s.shape.height_m));
  w.key("weight_kg").value(static_cast<double>(s.shape.weight_kg));
  w.key("neck_mm").value(static_cast<double>(s.shape.neck_mm));
  w.key("chest_mm").value(static_cast<double>(s.shape.chest_mm));
  w.key("waist_mm").value(static_cast<double>(s.shape.waist_mm));
  w.key("hip_mm").value(static_cast<double>(s.shape.hip_mm));
  w.key("thigh_mm").value(static_cast<double>(s.shape.thigh_mm));
  w.key("calf_mm").value(static_cast<double>(s.shape.calf_mm));
  w.key("upper_arm_mm").value(static_cast<double>(s.shape.upper_arm_mm));
  w.key("forearm_mm").value(static_cast<double>(s.shape.forearm_mm));
  w.endObject();

  w.key("ring_points").value(s.ring_points);
  w.endObject();
  return w.str();
}

std::string summaryText(const ReplayStats& s, const std::string& obj_dir, const std::string& stats_path) {
  std::string o;
  appendf(o, "drape-replay (Drape %s)\n", s.drape_version.c_str());
  o += "recording   " + s.recording + "\n";
  appendf(o, "            %s, %s, %u frames at %.1f Hz\n", formatName(s.format), layoutName(s.layout),
      s.recording_frames, static_cast<double>(s.recording_rate_hz));
  appendf(o, "frames      %u replayed, %u rejected, %u teleports, %llu non-finite outputs\n", s.frames,
      s.rejected_frames, s.teleports, static_cast<unsigned long long>(s.nonfinite));
  appendf(o, "body        %u vertices, %u triangles (ring_points %u), watertight %u/%u frames\n", s.vertices,
      s.triangles, s.ring_points, s.watertight_frames, s.frames - s.rejected_frames);
  appendf(o, "volume      %.2f L median (shape %.2f m, %.1f kg)\n", median(s.volume_l),
      static_cast<double>(s.shape.height_m), static_cast<double>(s.shape.weight_kg));
  if (!s.body_to_proxy_p95.empty())
    appendf(o, "proxies     %u ellipsoids (%s rule); fit P95 body->proxy %.1f mm, proxy->body %.1f mm (median of %zu frames)\n",
        s.proxy_count, s.proxy_rule == DRAPE_PROXY_RULE_PAPER ? "paper" : "drape", median(s.body_to_proxy_p95),
        median(s.proxy_to_body_p95), s.body_to_proxy_p95.size());
  o += "\n";
  appendf(o, "%-16s %10s %10s %10s %12s\n", "stage", "median ms", "p90 ms", "max ms", "paper ms");
  appendf(o, "%-16s %10s %10s %10s %12s\n", "skeleton", fmtMs(median(s.skeleton_ms)).c_str(),
      fmtMs(percentile(s.skeleton_ms, 90)).c_str(), fmtMs(maximum(s.skeleton_ms)).c_str(), "-");
  appendf(o, "%-16s %10s %10s %10s %12s\n", "body", fmtMs(median(s.body_ms)).c_str(),
      fmtMs(percentile(s.body_ms, 90)).c_str(), fmtMs(maximum(s.body_ms)).c_str(), fmtMs(kPaperBodyMs).c_str());
  appendf(o, "%-16s %10s %10s %10s %12s\n", "proxies", fmtMs(median(s.proxies_ms)).c_str(),
      fmtMs(percentile(s.proxies_ms, 90)).c_str(), fmtMs(maximum(s.proxies_ms)).c_str(), "~0");
  appendf(o, "%-16s %10s %10s %10s %12s\n", "push+update", fmtMs(median(s.ms_per_frame)).c_str(),
      fmtMs(percentile(s.ms_per_frame, 90)).c_str(), fmtMs(maximum(s.ms_per_frame)).c_str(), "-");
  o += "\n";
  if (!obj_dir.empty()) o += "obj         " + obj_dir + "/body_NNNNN.obj\n";
  if (!stats_path.empty()) o += "stats       " + stats_path + "\n";
  return o;
}

}  // namespace replay
