// The body mesh's connectivity, built once per model. Every tube is a run of quads between
// consecutive rings; the branch points are stitched so that every edge is shared by exactly two
// triangles, traversed once in each direction (closed and consistently wound):
//
//  - hips: the lowest torso ring is split into a right and a left half, closed by a crotch
//    bridge (a chain of extra vertices from the front-centre to the back-centre point); each half
//    plus the bridge is a loop stitched to its thigh's first ring;
//  - shoulders: between the top torso ring T (armpit level) and the neck's first ring N, a front
//    and a back strip join T's and N's front and back arcs; what is left on each side (T's side
//    arc going up into N's side arc) is a loop stitched to that arm's dynamic junction ring;
//  - head, hands and feet end in a fan to one apex vertex.
//
// Triangles are counter-clockwise seen from outside. For two rings L -> U along a chain (ring
// points advance from the frame's x towards its z axis) the triangles (L_j, U_j, L_j+1) and
// (L_j+1, U_j, U_j+1) face outwards; loops stitched to a chain's first ring are ordered so they
// turn the same way about the chain's direction.
#include "body/body_model.h"
#include "body/loop_stitch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

void BodyModel::buildTopology() {
  const int K = K_;
  indices_.clear();
  shoulderTrisL_.clear();
  shoulderTrisR_.clear();
  auto ringIndices = [&](int ring) {
    Loop l(K);
    for (int j = 0; j < K; ++j) l[j] = static_cast<uint32_t>(ring * K + j);
    return l;
  };

  // Tubes along every chain, and the apex fans at open ends.
  const Chain apexChains[5] = {Chain::Head, Chain::ArmL, Chain::ArmR, Chain::LegL, Chain::LegR};
  for (int c = 0; c < kChainCount; ++c) {
    for (int i = 0; i + 1 < chainCount_[c]; ++i) {
      const Loop L = ringIndices(chainFirst_[c] + i), U = ringIndices(chainFirst_[c] + i + 1);
      stitchEqual(L.data(), U.data(), K, true, indices_);
    }
  }
  for (int a = 0; a < 5; ++a) {
    const int c = static_cast<int>(apexChains[a]);
    const Loop L = ringIndices(chainFirst_[c] + chainCount_[c] - 1);
    const uint32_t apex = static_cast<uint32_t>(apexFirst_ + a);
    for (int j = 0; j < K; ++j) indices_.insert(indices_.end(), {L[j], apex, L[(j + 1) % K]});
  }

  // Hips. Ring P's point j sits at angle 2 pi j / K from forward towards the body's right, so
  // j in [0, K/2] is the right half. Leg rings turn the other way about their (downward) chain
  // direction, so each half loop is reversed before stitching.
  const Loop P = ringIndices(chainFirst_[static_cast<int>(Chain::Torso)]);
  Loop bridge(bridgeCount_);
  for (int b = 0; b < bridgeCount_; ++b) bridge[b] = static_cast<uint32_t>(bridgeFirst_ + b);
  {
    Loop right(P.begin(), P.begin() + K / 2 + 1);                // front -> right -> back
    right.insert(right.end(), bridge.rbegin(), bridge.rend());   // back -> front under the crotch
    std::reverse(right.begin(), right.end());
    stitchLoops(right, ringIndices(chainFirst_[static_cast<int>(Chain::LegR)]), positions_, indices_);

    Loop left(P.begin() + K / 2, P.end());                       // back -> left -> (front)
    left.push_back(P[0]);
    left.insert(left.end(), bridge.begin(), bridge.end());       // front -> back under the crotch
    std::reverse(left.begin(), left.end());
    stitchLoops(left, ringIndices(chainFirst_[static_cast<int>(Chain::LegL)]), positions_, indices_);
  }

  // Shoulders. T = top torso ring, N = first neck ring; arcs split at +-h around forward and back.
  const Loop T = ringIndices(chainFirst_[static_cast<int>(Chain::Torso)] + chainCount_[static_cast<int>(Chain::Torso)] - 1);
  const Loop N = ringIndices(chainFirst_[static_cast<int>(Chain::Head)]);
  const int h = std::max(1, K / 8);
  auto arc = [&](const Loop& ring, int from, int to) {  // inclusive, wrapping, increasing j
    Loop a;
    for (int j = from;; ++j) {
      a.push_back(ring[((j % K) + K) % K]);
      if (((j - to) % K) == 0) break;
    }
    return a;
  };
  {
    const Loop tf = arc(T, -h, h), nf = arc(N, -h, h);
    stitchEqual(tf.data(), nf.data(), static_cast<int>(tf.size()), false, indices_);
    const Loop tb = arc(T, K / 2 - h, K / 2 + h), nb = arc(N, K / 2 - h, K / 2 + h);
    stitchEqual(tb.data(), nb.data(), static_cast<int>(tb.size()), false, indices_);
  }
  for (bool leftSide : {false, true}) {
    // Right: T from front-right round to back-right, then N back round to front.
    const int from = leftSide ? K / 2 + h : h, to = leftSide ? K - h : K / 2 - h;
    Loop loop = arc(T, from, to);
    Loop up = arc(N, from, to);
    loop.insert(loop.end(), up.rbegin(), up.rend());
    const Chain arm = leftSide ? Chain::ArmL : Chain::ArmR;
    std::vector<uint32_t>& tris = leftSide ? shoulderTrisL_ : shoulderTrisR_;
    stitchLoops(loop, ringIndices(chainFirst_[static_cast<int>(arm)]), positions_, tris);
    indices_.insert(indices_.end(), tris.begin(), tris.end());
  }
}

}  // namespace drape
