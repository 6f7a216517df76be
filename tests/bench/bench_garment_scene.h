// The garment scene the cloth benchmarks share (bench_cloth.cpp, bench_opencl.cpp): a T-shirt
// template on the default body and, per frame of the bundled Kinect recording, the Drape-rule
// tracking ellipsoids and the pin targets, precomputed so a timed loop is cloth only.
#pragma once

#include "body/body_model.h"
#include "body/body_shape.h"
#include "cloth/garment_templates.h"
#include "cloth/garment_topology.h"
#include "proxies/proxy_builder.h"
#include "recording/recording.h"
#include "skeleton/layouts.h"
#include "skeleton/tracker.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace drape::bench {

// The bundled recording (samples/data), found from this file's path so no shared data is needed.
inline std::string bundledRecording() {
  std::string dir = __FILE__;
  dir = dir.substr(0, dir.find_last_of("/\\") + 1);
  return dir + "../../samples/data/Ges01_wavehand.csv";
}

// Everything a cloth step needs per recording frame, precomputed so the timed loop is cloth only:
// the Drape-rule tracking ellipsoids and the pin targets (ring centre + ring frame * pin_local).
struct GarmentScene {
  GarmentTopology topology;
  std::vector<std::vector<Ellipsoid>> ellipsoids;  // per frame
  std::vector<std::vector<Vec3>> pins;             // per frame
  Mat3 rotation = Mat3::Identity();                // rest pose -> first frame (collar ring)
  Vec3 pivot = Vec3::Zero(), shift = Vec3::Zero();
  std::string error;
};

inline std::unique_ptr<GarmentScene> buildGarmentScene(int target_particles) {
  auto out = std::make_unique<GarmentScene>();
  Recording rec;
  if (!readRecordingFile(bundledRecording(), 0, rec, out->error)) return out;
  const ResolvedShape shape = resolveShape(BodyShapeInput{});
  BodyModel body(shape, BodyModelParams{});
  ProxyBuilder proxies(ProxyRule::Drape);
  body.update(restPose(shape));
  GarmentTemplateParams gp;
  gp.kind = GarmentKind::TShirt;
  gp.target_particles = target_particles;
  GarmentMesh mesh;
  if (!makeGarmentTemplate(body, gp, mesh, out->error)) return out;
  const RingPose collar_rest = body.rings()[static_cast<size_t>(mesh.pin_ring[0])];
  TopologyParams tp;
  tp.pinned = mesh.pinned;
  if (!buildGarmentTopology(mesh.positions.data()->data(), mesh.positions.size(),
                            mesh.indices.data(), mesh.indices.size(), tp, out->topology,
                            out->error))
    return out;
  // Pin targets in topology().pinned order (sorted), from the template's pin order.
  std::map<uint32_t, size_t> pin_index;
  for (size_t i = 0; i < mesh.pinned.size(); ++i) pin_index[mesh.pinned[i]] = i;
  SkeletonTracker tracker;
  for (const RecordingFrame& f : rec.frames) {
    SkeletonPose raw;
    if (!mapToCanonical(rec.layout, f.joints.data(), static_cast<int>(f.joints.size()), raw,
                        out->error))
      return out;
    tracker.push(raw, f.time_s);
    body.update(tracker.pose());
    proxies.build(body, tracker.pose());
    out->ellipsoids.push_back(proxies.ellipsoids());
    std::vector<Vec3> pins;
    for (uint32_t p : out->topology.pinned) {
      const size_t i = pin_index[p];
      const RingPose& r = body.rings()[static_cast<size_t>(mesh.pin_ring[i])];
      pins.push_back(r.centre + r.frame * mesh.pin_local[i]);
    }
    out->pins.push_back(std::move(pins));
    if (out->pins.size() == 1) {
      const RingPose& c = body.rings()[static_cast<size_t>(mesh.pin_ring[0])];
      out->rotation = c.frame * collar_rest.frame.transpose();
      out->pivot = collar_rest.centre;
      out->shift = c.centre - collar_rest.centre;
    }
  }
  return out;
}

// Frame i of an endless ping-pong over the take (0 .. n-1, n-2 .. 1, ...): no jump at the wrap.
inline size_t pingPong(size_t i, size_t n) {
  if (n < 2) return 0;
  const size_t period = 2 * (n - 1), k = i % period;
  return k < n ? k : period - k;
}

}  // namespace drape::bench
