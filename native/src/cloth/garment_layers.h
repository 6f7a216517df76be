// Layered garments: a garment worn over others (a T-shirt over trousers, a dress over leggings)
// collides with the body's ellipsoids grown by how far the cloth under it stands off each of
// them, so it lies on that cloth instead of passing through it (docs/garments.md, "Layered
// garments").
//
// Why ellipsoids grown per ellipsoid rather than cloth against cloth: the garments already
// collide with nothing but ellipsoids, and a second garment's particles as colliders would cost
// a cloth-cloth broad phase every substep (the self-collision that multiplies other engines'
// frame time by ten, ../shared/ANCHORS.md). Cloth under a garment lies on the body, so how far it
// stands off an ellipsoid is nearly the same all over that ellipsoid and from one frame to the
// next: one radius increase per ellipsoid, measured once a step from where the cloth under it is,
// keeps the garment over it. Both cloth backends get the grown ellipsoids as they get the body's:
// nothing changes on the device.
#pragma once

#include "common/math.h"
#include "proxies/ellipsoid.h"

#include <cstdint>
#include <vector>

namespace drape {

// How far one garment's cloth stands off each ellipsoid: the shell a garment over it lies on.
class ClothShell {
 public:
  // Cloth farther than this off its nearest ellipsoid is not lying on it (a skirt's flare, a
  // loose fold): it does not count. 3 cm holds the templates' ease (2.5 cm) plus their 4 mm margin.
  static constexpr float kReachM = 0.03f;
  // An ellipsoid's offset is this quantile of the distances of the cloth on it, not the largest:
  // the largest is a fold (trousers stand 15-22 mm off the hips and thighs at the median on Ges01,
  // and up to the reach in their folds), and the garment over them, cut for the body, stretches
  // round whatever it is pushed out by. Priced over the eight shared takes (a T-shirt over
  // trousers, docs/garments.md "Layered garments"): the largest / 0.9 / 0.75 / the median leave
  // 5.9 / 6.7 / 7.3 / 17.3 % of the shirt's particles over the trousers under them on Ges01
  // (69.5 % unlayered) for a median P99 stretch 1.47 / 1.39 / 1.10 / 1.06 x the unlayered shirt's.
  static constexpr float kQuantile = 0.75f;
  // Which ellipsoid each particle lies on is searched afresh for one particle in this many each
  // measure, in turn (the search computes a particle's |q| in every ellipsoid whose bounding
  // sphere grown by the reach holds it; a sixteenth of 1 200 trousers particles took 0.012-0.019 ms
  // on the Zen 5 of 2026-11-30, so all at once 0.2-0.3 ms), so a particle's ellipsoid is at most
  // 16 steps old (0.5 s at 30 Hz: cloth keeps to its body part); every particle's distance to its
  // ellipsoid is measured every time.
  static constexpr int kHostEvery = 16;

  // Measures the cloth: its particle positions (xyz; w ignored) lying where `ellipsoids` are (the
  // ellipsoids at the end of the last step, refreshed: their cached to_unit is the unit map used).
  // Each particle lies on the ellipsoid it is deepest in or nearest to (the smallest |q| in that
  // ellipsoid's unit space, among those whose bounding sphere grown by kReachM holds it); its distance outside that ellipsoid ((|q| - 1) / |grad |q||: exact on a
  // sphere, to first order on an ellipsoid; 0 inside) counts when it is at most kReachM, and the
  // kQuantile of the distances that count on an ellipsoid is its offset (0: no cloth on it).
  // Non-finite positions are skipped.
  void measure(const Eigen::Vector4f* positions, size_t count, const std::vector<Ellipsoid>& ellipsoids);
  const std::vector<float>& offsets() const { return offsets_; }
  // The next measure searches every particle's ellipsoid afresh (new particles, a new body).
  void forgetHosts() { hosts_round_ = -1; }

 private:
  // Searches the ellipsoid of every particle (only < 0) or of those with i % kHostEvery == only.
  void findHosts(const Eigen::Vector4f* positions, size_t count, const std::vector<Ellipsoid>& ellipsoids, int only);
  std::vector<float> offsets_;
  std::vector<int32_t> host_;  // each particle's ellipsoid, -1 none
  int hosts_round_ = -1;       // the residue searched last (-1: none searched yet)
  size_t hosts_ellipsoids_ = 0;
  // Scratch, kept so that a measure allocates nothing once sizes settle.
  std::vector<Eigen::Vector4f> spheres_;  // each ellipsoid's centre, and its radius + reach squared
  std::vector<float> dist_, bucketed_;   // each particle's distance (-1: none); by ellipsoid
  std::vector<uint32_t> bucket_start_, fill_;
};

// The offsets a garment over others steps with: the largest of the shells under it, changing by
// at most the step limits, and the ellipsoids grown by them.
class LayerOffsets {
 public:
  // Growth per step at most (a step's grown ellipsoids move from the last step's offsets to this
  // one's across its substeps, like a body part: 1 cm per 1/30 s is 0.3 m/s), and shrinkage per
  // step at most (a fold that flattens for one frame does not let the garment over it sink).
  static constexpr float kMaxGrowthM = 0.01f;
  static constexpr float kMaxShrinkM = 0.002f;

  // Clears the offsets (the next step starts from 0: nothing under the garment yet).
  void reset() { offsets_.clear(); previous_.clear(); }
  // Starts a step: the offsets of the last step become the step's start offsets, and the new
  // ones start at 0 for `count` ellipsoids.
  void beginStep(size_t count);
  // A shell under the garment: the new offsets are the largest of the shells added.
  void addUnder(const std::vector<float>& shell);
  // Ends the step's measure: each new offset is limited to the last step's +kMaxGrowthM /
  // -kMaxShrinkM (and 0), unless !limited (a garment's first step, which places it).
  void endMeasure(bool limited = true);
  const std::vector<float>& offsets() const { return offsets_; }
  const std::vector<float>& startOffsets() const { return previous_; }
  bool any() const;  // an offset, new or at the start, above 0

  // `in` with every radius grown by offsets[k] (missing offsets: 0), refreshed. out is resized.
  static void grow(const std::vector<Ellipsoid>& in, const std::vector<float>& offsets, std::vector<Ellipsoid>& out);

 private:
  std::vector<float> offsets_, previous_;
};

}  // namespace drape
