// drape-proxy-fit: how closely the tracking ellipsoids follow the body mesh on recordings, for
// both construction rules side by side (the figures in docs/proxies.md).
// Usage: drape-proxy-fit RECORDING... (every frame measured, 256 samples per ellipsoid)
#include "body/body_model.h"
#include "proxies/fidelity.h"
#include "proxies/proxy_builder.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

using namespace drape;

namespace {

float median(std::vector<float> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0f : v[v.size() / 2];
}
float maxOf(const std::vector<float>& v) { return v.empty() ? 0.0f : *std::max_element(v.begin(), v.end()); }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: drape-proxy-fit RECORDING...\n");
    return 2;
  }
  std::printf("| recording | rule | ellipsoids | body->proxy P95 (median / worst frame) | max | proxy->body P95 (median / worst frame) | max | body outside |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int a = 1; a < argc; ++a) {
    Recording rec;
    std::string err;
    if (!readRecordingFile(argv[a], 0, rec, err)) {
      std::fprintf(stderr, "%s\n", err.c_str());
      return 2;
    }
    for (ProxyRule rule : {ProxyRule::Paper, ProxyRule::Drape}) {
      const ResolvedShape shape = resolveShape(BodyShapeInput{});
      BodyModel body(shape, BodyModelParams{});
      SkeletonTracker tracker;
      ProxyBuilder proxies(rule);
      proxies.build(body, restPose(shape));  // sizes fixed on the rest pose, as a context does
      TriangleBvh bvh;
      bvh.build(body.positions(), body.indices());
      std::vector<float> gapP95, gapMax, bulgeP95, bulgeMax, outside;
      for (size_t i = 0; i < rec.frames.size(); ++i) {
        SkeletonPose raw;
        if (!mapToCanonical(rec.layout, rec.frames[i].joints.data(), static_cast<int>(rec.frames[i].joints.size()), raw, err))
          return 1;
        tracker.push(raw, rec.frames[i].time_s);
        body.update(tracker.pose());
        proxies.build(body, tracker.pose());
        bvh.refit(body.positions());
        const auto& e = proxies.ellipsoids();
        const FidelityReport f = measureFidelity(body.positions(), body.indices(), e.data(), static_cast<int>(e.size()), bvh);
        gapP95.push_back(f.body_to_union_p95_mm);
        gapMax.push_back(f.body_to_union_max_mm);
        bulgeP95.push_back(f.union_to_body_p95_mm);
        bulgeMax.push_back(f.union_to_body_max_mm);
        outside.push_back(f.outside_fraction);
      }
      std::printf("| %s | %s | %zu | %.1f / %.1f | %.1f | %.1f / %.1f | %.1f | %.1f %% |\n",
                  std::filesystem::path(argv[a]).filename().string().c_str(), rule == ProxyRule::Paper ? "paper" : "drape",
                  proxies.ellipsoids().size(), median(gapP95), maxOf(gapP95), maxOf(gapMax), median(bulgeP95),
                  maxOf(bulgeP95), maxOf(bulgeMax), 100.0f * median(outside));
    }
  }
  return 0;
}
