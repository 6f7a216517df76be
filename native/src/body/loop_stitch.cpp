#include "body/loop_stitch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

void stitchEqual(const uint32_t* L, const uint32_t* U, int n, bool closed, std::vector<uint32_t>& out) {
  const int segments = closed ? n : n - 1;
  for (int j = 0; j < segments; ++j) {
    const int j1 = (j + 1) % n;
    out.insert(out.end(), {L[j], U[j], L[j1]});
    out.insert(out.end(), {L[j1], U[j], U[j1]});
  }
}

void stitchLoops(const Loop& L, Loop U, const std::vector<Vec3>& rest, std::vector<uint32_t>& out, int* rotation) {
  const int n = static_cast<int>(L.size()), m = static_cast<int>(U.size());
  int best = 0;
  float bestCost = std::numeric_limits<float>::max();
  const bool given = rotation != nullptr && *rotation >= 0 && *rotation < m;
  if (given) best = *rotation;
  for (int o = 0; o < m && !given; ++o) {
    float cost = 0.0f;
    for (int i = 0; i < n; ++i) {
      const int j = (o + static_cast<int>(std::lround(static_cast<double>(i) * m / n))) % m;
      cost += (rest[L[i]] - rest[U[j]]).squaredNorm();
    }
    if (cost < bestCost) {
      bestCost = cost;
      best = o;
    }
  }
  if (rotation) *rotation = best;
  std::rotate(U.begin(), U.begin() + best, U.end());
  int i = 0, j = 0;
  while (i < n || j < m) {
    // Advance L while its next parameter (i+1)/n is not beyond U's next (j+1)/m.
    const bool advanceL = j == m || (i < n && static_cast<long>(i + 1) * m <= static_cast<long>(j + 1) * n);
    if (advanceL) {
      out.insert(out.end(), {L[i % n], U[j % m], L[(i + 1) % n]});
      ++i;
    } else {
      out.insert(out.end(), {L[i % n], U[j % m], U[(j + 1) % m]});
      ++j;
    }
  }
}

}  // namespace drape
