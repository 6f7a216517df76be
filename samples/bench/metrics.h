// Error figures measured the same way for every simulator drape-bench runs (Drape at any setting,
// Bullet's soft body): any garment vertex array against the body mesh of the same frame, the
// structural edges of the garment mesh against their rest lengths, the tracking ellipsoids, and a
// reference run's vertices. Everything pools per-frame samples so that P99 and max are taken over
// all vertices (or edges) of all measured frames.
#pragma once

#include <drape/drape.h>

#include "proxies/mesh_bvh.h"

#include <cstdint>
#include <vector>

namespace bench {

// Percentile by nearest rank (p in (0, 100]) of a copy of v; NaN when empty.
double percentile(std::vector<double> v, double p);
double median(const std::vector<double>& v);
double mean(const std::vector<double>& v);
double maximum(const std::vector<double>& v);

// This frame's body mesh as the penetration meters probe it (drape's TriangleBvh, the structure
// drape_garment_measure uses): one per frame, however many garments are measured against it.
class BodySurface {
 public:
  // body: this frame's body mesh (drape_context_read_body_mesh). Returns false if unusable.
  bool set(const std::vector<drape_vec3>& positions, const std::vector<uint32_t>& indices);
  // Depth of v inside the body (inside by the winding number), mm; 0 outside.
  double depthMm(const drape_vec3& v) const;

 private:
  drape::TriangleBvh bvh_;
  std::vector<drape::Vec3> scratch_;
};

// Depth of garment vertices inside the body mesh, pooled over frames.
class PenetrationMeter {
 public:
  void addFrame(const BodySurface& body, const drape_vec3* vertices, size_t count);
  double p99Mm() const;
  double maxMm() const;
  double deeperThan2mmFraction() const;  // vertex-frames more than 2 mm inside
  // Vertex-frames inside the body at any depth: the figure ANCHORS.md gives its peers as "cloth
  // inside the body" (NvCloth 0.40 %, Bullet 4 x 10 2.2 % of the particles).
  double insideFraction() const;
  size_t samples() const { return depth_mm_.size(); }

 private:
  std::vector<double> depth_mm_;
  size_t deep_ = 0, inside_ = 0;
};

// Openings (the mesh's boundary loops: hem, collar, cuffs) off the body part they went round, counted
// the same way for every engine's vertices: the library's measure (drape_garment_accuracy.openings,
// cloth/garment_openings.h: Gauss linking of loop and body-part polyline, bound at >= 0.75, off
// below 0.5 of the same sign) on body parts built from the tracking ellipsoids, which every engine
// here meets, instead of the library's rings: per chain the mean centre of each ring's ellipsoids, in
// ring order (the spine: torso, then head; 0.5 m on below the pelvis, legs from 0.15 m above their
// first ring, as the library's), each limb and the head on to its last ellipsoid's end.
class OpeningsMeter {
 public:
  // The openings of `indices` at `x` (the dressed garment of the first frame) and the body part
  // each goes round there; openings round none are not tracked.
  void bind(const std::vector<uint32_t>& indices, const drape_vec3* x, size_t n,
            const std::vector<drape_ellipsoid>& ellipsoids);
  void addFrame(const drape_vec3* x, const std::vector<drape_ellipsoid>& ellipsoids);
  size_t tracked() const { return openings_.size(); }
  // Frames with one or more tracked openings off their body part, over the frames added.
  double offFraction() const;

 private:
  struct Opening {
    std::vector<uint32_t> loop;
    size_t part = 0;
    int sign = 1;
  };
  std::vector<Opening> openings_;
  std::vector<std::vector<drape::Vec3>> parts_;
  std::vector<drape::Vec3> loop_;
  size_t frames_ = 0, off_frames_ = 0;
};

// Stretch |len| / rest - 1 of each structural edge (each undirected triangle edge once).
class StretchMeter {
 public:
  void setMesh(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& rest);
  // New rest lengths for the same edges (the garment was cut again: drape_garment_stats.refits);
  // the samples so far stay.
  void setRest(const std::vector<drape_vec3>& rest);
  void addFrame(const drape_vec3* vertices);
  double p99() const { return percentile(samples_, 99.0); }
  double max() const { return maximum(samples_); }
  size_t edges() const { return a_.size(); }

 private:
  std::vector<uint32_t> a_, b_;
  std::vector<double> rest_, samples_;
};

// A garment's error figures from its meters, into a PeerSide or a RunResult (the same field names):
// stretch P99 and max, penetration P99, max, the shares deeper than 2 mm and inside at any depth,
// `inside` per frame's mean.
template <class Out>
void readErrors(const StretchMeter& stretch, const PenetrationMeter& pen, const std::vector<double>& inside, Out& out) {
  out.stretch_p99 = stretch.p99();
  out.stretch_max = stretch.max();
  out.penetration_p99_mm = pen.p99Mm();
  out.penetration_max_mm = pen.maxMm();
  out.deeper_than_2mm = pen.deeperThan2mmFraction();
  out.in_body = pen.insideFraction();
  out.inside_mean = mean(inside);
}

// Vertices strictly inside (> 0.1 mm, as drape_garment_measure counts) any of the ellipsoids,
// `skip` marking vertices to leave out (pinned ones).
uint32_t countInsideEllipsoids(const drape_vec3* vertices, size_t count, const std::vector<uint8_t>& skip,
                               const std::vector<drape_ellipsoid>& ellipsoids);

// Per-frame distance to a reference run's vertices (same mesh, same frame): RMS and max in mm,
// each averaged over the frames added.
class DeviationMeter {
 public:
  void addFrame(const drape_vec3* run, const drape_vec3* reference, size_t count);
  double rmsMm() const { return mean(rms_mm_); }
  double maxMm() const { return mean(max_mm_); }
  size_t frames() const { return rms_mm_.size(); }

 private:
  std::vector<double> rms_mm_, max_mm_;
};

}  // namespace bench
