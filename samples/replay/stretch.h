// Garment stretch pooled over a whole replay: every structural edge (each undirected edge of the
// garment's triangles, once) of every frame, against its rest length. Memory is bounded whatever
// the run's length: a fixed-bin histogram of the stretch |len| / rest - 1 in 0.01 % bins from
// -100 % to +1000 %, an overflow count above, and the exact maximum.
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <vector>

namespace replay {

class StretchAccumulator {
 public:
  static constexpr double kBinWidth = 1e-4;  // 0.01 %
  static constexpr double kLow = -1.0;       // an edge of length 0
  static constexpr double kHigh = 10.0;      // +1000 %; above: the overflow count

  // The edges of the triangle list (each undirected edge once) and their rest lengths from
  // `rest` (drape_garment_read_rest_positions). Edges of rest length 0 are left out, and with
  // max_index_gap > 0 those whose two vertex indices differ by more (the body mesh's stitches
  // between tubes, whose vertices are stored ring by ring: ReplayStats::body_tube_stretch).
  void setMesh(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& rest,
               uint32_t max_index_gap = 0);

  // New rest lengths for the same edges (the garment was refitted: drape_garment_stats.refits);
  // the samples so far stay. Edges whose new rest length is 0 keep the old one.
  void setRest(const std::vector<drape_vec3>& rest);

  // Adds one frame's stretch samples. Edges with a non-finite length are skipped (the caller
  // counts non-finite positions).
  void addFrame(const std::vector<drape_vec3>& positions);

  size_t edgeCount() const { return a_.size(); }
  uint64_t samples() const { return samples_; }
  // NaN when there are no samples.
  double max() const;
  // The fraction of all samples above `stretch` (to the bin: samples in the bin holding it count
  // as above), NaN when empty.
  double fractionAbove(double stretch) const;
  // Nearest-rank p-th percentile (p in (0, 100]) of all samples: the upper edge of the bin holding
  // that rank (so at most 0.01 % above the exact value), never above max(). NaN when empty.
  double percentile(double p) const;

 private:
  std::vector<uint32_t> a_, b_;
  std::vector<float> rest_;
  std::vector<uint64_t> bins_;
  uint64_t overflow_ = 0;
  uint64_t samples_ = 0;
  double max_ = 0.0;
};

// The triangles of `indices` (3 per triangle, into `positions`) whose three vertices all lie within
// `radius` of a point of `near` and whose edges are all at least `min_edge` long: the part of the
// body mesh a garment covers (near = the garment's vertices), for the body's own surface stretch
// under it (ReplayStats::body_stretch). A uniform hash grid of `near`; O(|near| + |positions|).
std::vector<uint32_t> trianglesNear(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& positions,
                                    const std::vector<drape_vec3>& near, float radius, float min_edge);

}  // namespace replay
