#include "cloth/garment_layers.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

void ClothShell::findHosts(const Eigen::Vector4f* positions, size_t count, const std::vector<Ellipsoid>& ellipsoids,
                           int only) {
  if (only < 0) host_.assign(count, -1);
  // Each ellipsoid's bounding sphere grown by the reach: the ellipsoids a particle may lie on.
  const size_t m = ellipsoids.size();
  spheres_.resize(m);
  for (size_t k = 0; k < m; ++k) {
    const Ellipsoid& e = ellipsoids[k];
    const bool ok = isFinite(e.centre) && isFinite(e.radii) && e.radii.minCoeff() > 0.0f && e.rotation.allFinite();
    const float r = e.radii.maxCoeff() + kReachM;
    spheres_[k] = ok ? Eigen::Vector4f(e.centre.x(), e.centre.y(), e.centre.z(), r * r)
                     : Eigen::Vector4f(0.0f, 0.0f, 0.0f, -1.0f);  // r^2 = -1: never near
  }
  for (size_t i = 0; i < count; ++i) {
    if (only >= 0 && static_cast<int>(i % kHostEvery) != only) continue;
    host_[i] = -1;
    const Vec3 x = positions[i].head<3>();
    if (!isFinite(x)) continue;
    // The smallest |q|^2 among the ellipsoids near it.
    float best = std::numeric_limits<float>::infinity();
    for (size_t k = 0; k < m; ++k) {
      const Eigen::Vector4f& sk = spheres_[k];
      const Vec3 d = x - sk.head<3>();
      if (!(d.squaredNorm() <= sk.w())) continue;
      const float q2 = (ellipsoids[k].to_unit * d).squaredNorm();
      if (q2 < best) {
        best = q2;
        host_[i] = static_cast<int32_t>(k);
      }
    }
  }
}

void ClothShell::measure(const Eigen::Vector4f* positions, size_t count, const std::vector<Ellipsoid>& ellipsoids) {
  offsets_.assign(ellipsoids.size(), 0.0f);
  if (positions == nullptr || count == 0 || ellipsoids.empty()) return;
  if (hosts_round_ < 0 || host_.size() != count || hosts_ellipsoids_ != ellipsoids.size()) {
    findHosts(positions, count, ellipsoids, -1);
    hosts_round_ = 0;
    hosts_ellipsoids_ = ellipsoids.size();
  } else {
    hosts_round_ = (hosts_round_ + 1) % kHostEvery;
    findHosts(positions, count, ellipsoids, hosts_round_);
  }
  // Each particle's distance outside its ellipsoid, when within reach, bucketed by ellipsoid.
  dist_.resize(count);
  bucket_start_.assign(ellipsoids.size() + 1, 0);
  for (size_t i = 0; i < count; ++i) {
    dist_[i] = -1.0f;
    const int32_t k = host_[i];
    const Vec3 x = positions[i].head<3>();
    if (k < 0 || !isFinite(x)) continue;
    const Ellipsoid& e = ellipsoids[static_cast<size_t>(k)];
    const Mat3& to_unit = e.to_unit;
    const Vec3 q = to_unit * (x - e.centre);
    const float q2 = q.squaredNorm();
    float d = 0.0f;
    if (q2 > 1.0f) {
      // (|q| - 1) / |grad |q||, grad |q| = to_unit^T q / |q|: exact on a sphere, to first order
      // on an ellipsoid.
      const float s = std::sqrt(q2);
      const float g = (to_unit.transpose() * q).norm() / s;
      d = g > 0.0f ? (s - 1.0f) / g : std::numeric_limits<float>::infinity();
    }
    if (!(d <= kReachM)) continue;
    dist_[i] = d;
    ++bucket_start_[static_cast<size_t>(k) + 1];
  }
  for (size_t k = 0; k < ellipsoids.size(); ++k) bucket_start_[k + 1] += bucket_start_[k];
  bucketed_.resize(bucket_start_[ellipsoids.size()]);
  fill_.assign(bucket_start_.begin(), bucket_start_.end() - 1);
  for (size_t i = 0; i < count; ++i)
    if (dist_[i] >= 0.0f) bucketed_[fill_[static_cast<size_t>(host_[i])]++] = dist_[i];
  // The quantile per ellipsoid (nearest rank).
  for (size_t k = 0; k < ellipsoids.size(); ++k) {
    const uint32_t a = bucket_start_[k], b = bucket_start_[k + 1];
    if (a == b) continue;
    const auto rank = static_cast<uint32_t>(kQuantile * static_cast<float>(b - a - 1) + 0.5f);
    std::nth_element(bucketed_.begin() + a, bucketed_.begin() + a + rank, bucketed_.begin() + b);
    offsets_[k] = bucketed_[a + rank];
  }
}

void LayerOffsets::beginStep(size_t count) {
  previous_ = offsets_;
  previous_.resize(count, 0.0f);
  offsets_.assign(count, 0.0f);
}

void LayerOffsets::addUnder(const std::vector<float>& shell) {
  for (size_t k = 0; k < offsets_.size() && k < shell.size(); ++k) offsets_[k] = std::max(offsets_[k], shell[k]);
}

bool LayerOffsets::any() const {
  const auto positive = [](float v) { return v > 0.0f; };
  return std::any_of(offsets_.begin(), offsets_.end(), positive) ||
         std::any_of(previous_.begin(), previous_.end(), positive);
}

void LayerOffsets::endMeasure(bool limited) {
  previous_.resize(offsets_.size(), 0.0f);
  if (!limited) return;
  for (size_t k = 0; k < offsets_.size(); ++k) {
    const float p = previous_[k];
    offsets_[k] = std::max(0.0f, std::clamp(offsets_[k], p - kMaxShrinkM, p + kMaxGrowthM));
  }
}

void LayerOffsets::grow(const std::vector<Ellipsoid>& in, const std::vector<float>& offsets, std::vector<Ellipsoid>& out) {
  out = in;  // same size after the first step: no allocation
  for (size_t k = 0; k < out.size() && k < offsets.size(); ++k) {
    if (!(offsets[k] > 0.0f)) continue;
    out[k].radii += Vec3::Constant(offsets[k]);
    out[k].refresh();
  }
}

}  // namespace drape
