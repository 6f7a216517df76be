// Full pipeline vs adaptive pipeline, side by side in one run (docs/adaptive.md).
//
// For each garment (skirt, T-shirt, dress, trousers) and each scene (the shared real takes, and a
// still pose held for 10 s), two contexts receive the same frames: one with every adaptive option
// off, one with the defaults (proxy culling, stages on demand, sleeping). Their steps alternate
// frame by frame, so both see the same machine load; only drape::Context::step (the work the host
// pays for every frame: skeleton filter, body, ellipsoids, cloth) is timed. The error figures are
// measured after the step, outside the timing, on every third frame: per-frame P99 stretch of the
// structural edges (median over the measured frames), P99 depth of garment vertices inside the
// body mesh (median) and particles inside an ellipsoid of their groups (summed).
//
//   drape_bench_adaptive [--particles N] [--still-seconds S] [--takes a,b,...]
// Prints a Markdown table. Shared recordings: ../shared/data or $DRAPE_SHARED_DATA.
#include "capi/context.h"
#include "cloth/garment_templates.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace drape;
using Clock = std::chrono::steady_clock;

std::string sharedDir() {
  if (const char* env = std::getenv("DRAPE_SHARED_DATA")) return env;
  return DRAPE_SHARED_DATA_DIR;
}

drape_context_desc defaultDesc() {
  // The C ABI's defaults (drape_context_desc_init), so a field added to the desc gets its default.
  drape_context_desc d;
  drape_context_desc_init(&d);
  return d;
}

struct Frame {
  drape_skeleton_frame frame{};
  std::vector<drape_joint> joints;
  float dt = 1.0f / 30.0f;
};

std::vector<Frame> framesOf(const Recording& rec) {
  std::vector<Frame> out(rec.frames.size());
  double prev = rec.frames.empty() ? 0.0 : rec.frames.front().time_s - 1.0 / 30.0;
  for (size_t i = 0; i < rec.frames.size(); ++i) {
    const RecordingFrame& f = rec.frames[i];
    Frame& o = out[i];
    o.joints.resize(f.joints.size());
    for (size_t j = 0; j < f.joints.size(); ++j) {
      o.joints[j].position = {f.joints[j].position.x(), f.joints[j].position.y(), f.joints[j].position.z()};
      o.joints[j].tracking_state = static_cast<int32_t>(f.joints[j].state);
    }
    o.frame.struct_size = sizeof(o.frame);
    o.frame.layout = static_cast<int32_t>(rec.layout);
    o.frame.joint_count = static_cast<uint32_t>(o.joints.size());
    o.frame.timestamp_s = f.time_s;
    o.dt = static_cast<float>(std::clamp(f.time_s - prev, 1e-4, 10.0));
    prev = f.time_s;
  }
  for (Frame& o : out) o.frame.joints = o.joints.data();
  return out;
}

// The default body's rest pose (arms down, as the shared takes' people mostly stand), in Kinect v2
// joint order, held still at 30 Hz.
std::vector<Frame> stillPose(double seconds) {
  const SkeletonPose pose = restPose(resolveShape(BodyShapeInput{}), 65.0f);
  static const Joint kMap[25] = {
      Joint::Pelvis, Joint::SpineMid, Joint::Neck, Joint::Head, Joint::ShoulderL, Joint::ElbowL,
      Joint::WristL, Joint::HandL, Joint::ShoulderR, Joint::ElbowR, Joint::WristR, Joint::HandR,
      Joint::HipL, Joint::KneeL, Joint::AnkleL, Joint::FootL, Joint::HipR, Joint::KneeR,
      Joint::AnkleR, Joint::FootR, Joint::SpineShoulder, Joint::HandL, Joint::HandL, Joint::HandR,
      Joint::HandR};
  const int n = static_cast<int>(seconds * 30.0);
  std::vector<Frame> out(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    Frame& o = out[static_cast<size_t>(i)];
    o.joints.resize(25);
    for (int j = 0; j < 25; ++j) {
      const Vec3& p = pose.position[static_cast<size_t>(kMap[j])];
      o.joints[static_cast<size_t>(j)].position = {p.x(), p.y(), p.z() + 2.5f};
      o.joints[static_cast<size_t>(j)].tracking_state = DRAPE_TRACKING_TRACKED;
    }
    o.frame.struct_size = sizeof(o.frame);
    o.frame.layout = DRAPE_LAYOUT_KINECT2;
    o.frame.joint_count = 25;
    o.frame.timestamp_s = i / 30.0;
  }
  for (Frame& o : out) o.frame.joints = o.joints.data();
  return out;
}

struct Side {
  std::unique_ptr<Context> ctx;
  GarmentSim* garment = nullptr;
  std::vector<double> ms, p99, pen, built;
  uint64_t inside = 0;
};

bool makeSide(Side& s, GarmentKind kind, int particles, bool adaptive, std::string& err) {
  s.ctx = std::make_unique<Context>(defaultDesc());
  if (!adaptive) {
    PipelineOptions o;
    o.cull_proxies = o.stages_on_demand = o.sleep = false;
    s.ctx->setPipelineOptions(o);
  }
  GarmentTemplateParams tp;
  tp.kind = kind;
  tp.target_particles = particles;
  GarmentMesh mesh;
  if (!makeGarmentTemplate(s.ctx->restBody(), tp, mesh, err)) return false;
  auto g = GarmentSim::create(mesh, TopologyParams{}, ClothSolverKind::Xpbd, GarmentSimParams{}, 0.5f,
                              s.ctx->restBody(), s.ctx->restEllipsoids(), s.ctx->restEllipsoidGroups(), err);
  if (!g) return false;
  s.garment = s.ctx->adoptGarment(std::move(g));
  return true;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}
double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

bool runScene(const std::string& scene, const std::vector<Frame>& frames, GarmentKind kind, int particles) {
  std::string err;
  Side full, fast;
  if (!makeSide(full, kind, particles, false, err) || !makeSide(fast, kind, particles, true, err)) {
    std::fprintf(stderr, "garment: %s\n", err.c_str());
    return false;
  }
  uint64_t slept = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const Frame& f = frames[i];
    // Alternate which side goes first, so neither always runs on a warmer cache.
    Side* order[2] = {&full, &fast};
    if (i % 2) std::swap(order[0], order[1]);
    for (Side* s : order) {
      const auto t0 = Clock::now();
      std::string e;
      if (s->ctx->pushFrame(f.frame, e) != DRAPE_OK || s->ctx->step(f.dt, e) != DRAPE_OK) {
        std::fprintf(stderr, "%s frame %zu: %s\n", scene.c_str(), i, e.c_str());
        return false;
      }
      s->ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
      // Before the measurement below builds every ellipsoid for its own use.
      s->built.push_back(s->ctx->skipCounters().proxies_built);
    }
    if (i % 3 == 2) {
      for (Side* s : {&full, &fast}) {
        const GarmentAccuracy a = s->ctx->measureGarment(*s->garment);
        s->p99.push_back(a.stretch.p99);
        s->pen.push_back(a.body_penetration_p99_mm);
        s->inside += a.proxy_inside;
      }
    }
  }
  const SkipCounters c = fast.ctx->skipCounters();
  slept = c.frames_slept;
  std::printf("| %s | %s | %zu | %.3f / %.3f | %.3f / %.3f | %.2fx | %.2fx | %.0f/%u | %.1f %% | %.3f / %.3f | %.2f / %.2f | %llu / %llu |\n",
              garmentKindName(kind), scene.c_str(), frames.size(), median(full.ms), median(fast.ms), mean(full.ms),
              mean(fast.ms), median(full.ms) / std::max(median(fast.ms), 1e-9), mean(full.ms) / std::max(mean(fast.ms), 1e-9),
              median(fast.built), c.proxies_available, 100.0 * static_cast<double>(slept) / static_cast<double>(frames.size()),
              median(full.p99), median(fast.p99), median(full.pen), median(fast.pen),
              static_cast<unsigned long long>(full.inside), static_cast<unsigned long long>(fast.inside));
  std::fflush(stdout);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int particles = 2000;
  double stillSeconds = 10.0;
  std::vector<std::string> takes = {"kinect_v2_msft_labanotation/Ges01_wavehand.csv",
                                    "kinect_v2_msft_labanotation/Ges02_balancinghands.csv",
                                    "kinect_v2_msft_labanotation/Ges04_comehere.csv",
                                    "kinect_v2_msft_labanotation/KinectReader_joints_closerange.csv",
                                    "cmu_mocap_bvh/131_03.bvh"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--particles" && i + 1 < argc) {
      particles = std::atoi(argv[++i]);
    } else if (a == "--still-seconds" && i + 1 < argc) {
      stillSeconds = std::atof(argv[++i]);
    } else if (a == "--takes" && i + 1 < argc) {
      takes.clear();
      std::string list = argv[++i], item;
      for (char ch : list + ",") {
        if (ch == ',') {
          if (!item.empty()) takes.push_back(item);
          item.clear();
        } else {
          item += ch;
        }
      }
    } else {
      std::fprintf(stderr, "usage: %s [--particles N] [--still-seconds S] [--takes a,b,...]\n", argv[0]);
      return 2;
    }
  }
  std::string cpu = "unknown CPU";
  {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
      if (line.rfind("model name", 0) == 0) {
        cpu = line.substr(line.find(':') + 2);
        break;
      }
  }
  std::printf("CPU: %s; %d-particle template garments, XPBD, one thread\n\n", cpu.c_str(), particles);
  std::printf("| garment | scene | frames | step ms median full / adaptive | mean full / adaptive | speed-up (median) "
              "| speed-up (mean) | ellipsoids built (median frame) | frames slept | P99 stretch full / adaptive "
              "| penetration P99 mm full / adaptive | proxy_inside full / adaptive |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<std::pair<std::string, std::vector<Frame>>> scenes;
  for (const std::string& t : takes) {
    const std::filesystem::path p = std::filesystem::path(sharedDir()) / t;
    Recording rec;
    std::string err;
    if (!std::filesystem::exists(p) || !readRecordingFile(p.string(), 0, rec, err)) {
      std::fprintf(stderr, "skipping %s: %s\n", t.c_str(), err.empty() ? "not found" : err.c_str());
      continue;
    }
    scenes.push_back({std::filesystem::path(t).filename().string(), framesOf(rec)});
  }
  scenes.push_back({"still pose " + std::to_string(static_cast<int>(stillSeconds)) + " s", stillPose(stillSeconds)});
  for (GarmentKind kind : {GarmentKind::Skirt, GarmentKind::TShirt, GarmentKind::Dress, GarmentKind::Trousers})
    for (const auto& [name, frames] : scenes)
      if (!runScene(name, frames, kind, particles)) return 1;
  return 0;
}
