#include "proxies/mesh_collider.h"

#include <cmath>
#include <limits>

namespace drape {
namespace {

template <bool kBruteForce>
MeshCollisionStats collide(const TriangleBvh& mesh, Eigen::Vector4f* positions, size_t count,
                           float margin_m) {
  MeshCollisionStats stats;
  if (!positions || mesh.empty()) return stats;
  const float margin = margin_m >= 0.0f ? margin_m : 0.0f;  // NaN / negative -> 0
  for (size_t i = 0; i < count; ++i) {
    Eigen::Vector4f& x = positions[i];
    if (!(x.w() > 0.0f)) continue;
    Vec3 p = x.head<3>();
    if (!isFinite(p)) continue;
    // Up to kMeshCollisionPasses projections, each checked by the next query. A projection that
    // lands inside behind a wall facing the previous one has crossed a gap narrower than the
    // margin: the particle goes to the middle of the gap (as far from both walls as it can be) and
    // stops there. Otherwise it ends at the best position seen (largest signed distance).
    Vec3 best = p;
    float best_sd = -std::numeric_limits<float>::infinity();
    bool contact = false, gap = false;
    uint32_t moved = 0;
    Vec3 prev_point = Vec3::Zero(), prev_normal = Vec3::Zero();
    for (int query = 0; query <= kMeshCollisionPasses + 1; ++query) {
      const TriangleBvh::Hit h = kBruteForce ? mesh.closestBruteForce(p) : mesh.closest(p);
      if (h.triangle < 0) break;
      const float sd = TriangleBvh::hitSign(p, h) * h.distance;
      if (sd > best_sd) {
        best_sd = sd;
        best = p;
      }
      if (sd >= margin || gap) break;
      contact = true;
      if (moved > 0 && sd < 0.0f && h.pseudo_normal.dot(prev_normal) < 0.0f) {
        p = 0.5f * (prev_point + h.point);
        gap = true;
        continue;  // one more query scores the midpoint
      }
      if (moved == static_cast<uint32_t>(kMeshCollisionPasses)) break;
      prev_point = h.point;
      prev_normal = h.pseudo_normal;
      p = h.point + margin * h.pseudo_normal;
      ++moved;
    }
    if (contact) {
      x.head<3>() = best;
      ++stats.contacts;
      stats.passes += moved;
    }
  }
  return stats;
}

}  // namespace

MeshCollisionStats collideWithMesh(const TriangleBvh& mesh, Eigen::Vector4f* positions,
                                   size_t count, float margin_m) {
  return collide<false>(mesh, positions, count, margin_m);
}

MeshCollisionStats collideWithMeshBruteForce(const TriangleBvh& mesh, Eigen::Vector4f* positions,
                                             size_t count, float margin_m) {
  return collide<true>(mesh, positions, count, margin_m);
}

}  // namespace drape
