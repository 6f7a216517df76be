// Random vectors drawn in a fixed order. The arguments of one call (Vec3(u(rng), u(rng), u(rng)))
// are evaluated in an order the compiler picks: g++ goes right to left, clang left to right, so
// the release tree (g++) and the sanitizer tree (clang) would test different samples and a failure
// in one would not reproduce in the other. Here every draw is its own statement: x, then y, then
// z (then w). Tests that scale or offset single draws name them one per statement the same way.
// A braced list T{u(rng), u(rng)} and a declaration list `a = u(rng), b = u(rng);` are already
// evaluated left to right and need neither.
#pragma once

#include "common/math.h"

namespace drape::test {

template <class Dist, class Gen>
Vec3 draw3(Dist& d, Gen& g) {
  const float x = d(g);
  const float y = d(g);
  const float z = d(g);
  return Vec3(x, y, z);
}

template <class Dist, class Gen>
Eigen::Vector4f draw4(Dist& d, Gen& g) {
  const float x = d(g);
  const float y = d(g);
  const float z = d(g);
  const float w = d(g);
  return Eigen::Vector4f(x, y, z, w);
}

}  // namespace drape::test
