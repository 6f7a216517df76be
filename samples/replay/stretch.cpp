#include "stretch.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

namespace replay {

namespace {
constexpr size_t kBins = static_cast<size_t>((StretchAccumulator::kHigh - StretchAccumulator::kLow) /
                                                 StretchAccumulator::kBinWidth +
                                             0.5);
}  // namespace

void StretchAccumulator::setMesh(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& rest,
                                 uint32_t max_index_gap) {
  std::vector<uint64_t> edges;
  edges.reserve(indices.size());
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = indices[t + static_cast<size_t>(e)], j = indices[t + static_cast<size_t>((e + 1) % 3)];
      if (i == j || i >= rest.size() || j >= rest.size()) continue;
      if (max_index_gap > 0 && (i > j ? i - j : j - i) > max_index_gap) continue;
      edges.push_back((static_cast<uint64_t>(std::min(i, j)) << 32) | std::max(i, j));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  a_.clear();
  b_.clear();
  rest_.clear();
  for (uint64_t key : edges) {
    const uint32_t i = static_cast<uint32_t>(key >> 32), j = static_cast<uint32_t>(key & 0xffffffffu);
    const double dx = static_cast<double>(rest[i].x) - rest[j].x, dy = static_cast<double>(rest[i].y) - rest[j].y,
                 dz = static_cast<double>(rest[i].z) - rest[j].z;
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(len > 0.0) || !std::isfinite(len)) continue;
    a_.push_back(i);
    b_.push_back(j);
    rest_.push_back(static_cast<float>(len));
  }
  bins_.assign(kBins, 0);
  overflow_ = 0;
  samples_ = 0;
  max_ = -std::numeric_limits<double>::infinity();
}

void StretchAccumulator::setRest(const std::vector<drape_vec3>& rest) {
  for (size_t k = 0; k < a_.size(); ++k) {
    if (a_[k] >= rest.size() || b_[k] >= rest.size()) continue;
    const drape_vec3& u = rest[a_[k]];
    const drape_vec3& v = rest[b_[k]];
    const double dx = static_cast<double>(u.x) - v.x, dy = static_cast<double>(u.y) - v.y,
                 dz = static_cast<double>(u.z) - v.z;
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (len > 0.0 && std::isfinite(len)) rest_[k] = static_cast<float>(len);
  }
}

void StretchAccumulator::addFrame(const std::vector<drape_vec3>& p) {
  for (size_t k = 0; k < a_.size(); ++k) {
    const drape_vec3& u = p[a_[k]];
    const drape_vec3& v = p[b_[k]];
    const double dx = static_cast<double>(u.x) - v.x, dy = static_cast<double>(u.y) - v.y,
                 dz = static_cast<double>(u.z) - v.z;
    const double s = std::sqrt(dx * dx + dy * dy + dz * dz) / rest_[k] - 1.0;
    if (!std::isfinite(s)) continue;
    ++samples_;
    max_ = std::max(max_, s);
    const double bin = std::floor((s - kLow) / kBinWidth);
    if (bin >= static_cast<double>(kBins)) ++overflow_;
    else ++bins_[bin < 0.0 ? 0 : static_cast<size_t>(bin)];
  }
}

double StretchAccumulator::max() const {
  return samples_ == 0 ? std::numeric_limits<double>::quiet_NaN() : max_;
}

double StretchAccumulator::percentile(double p) const {
  if (samples_ == 0) return std::numeric_limits<double>::quiet_NaN();
  // Nearest rank: the smallest value with at least p % of the samples at or below it.
  uint64_t rank = static_cast<uint64_t>(std::ceil(p / 100.0 * static_cast<double>(samples_)));
  rank = std::min(std::max<uint64_t>(rank, 1), samples_);
  uint64_t seen = 0;
  for (size_t i = 0; i < bins_.size(); ++i) {
    seen += bins_[i];
    if (seen >= rank) return std::min(kLow + static_cast<double>(i + 1) * kBinWidth, max_);
  }
  return max_;  // the rank lies in the overflow: only the maximum is known exactly
}

double StretchAccumulator::fractionAbove(double stretch) const {
  if (samples_ == 0) return std::numeric_limits<double>::quiet_NaN();
  const double first = std::floor((stretch - kLow) / kBinWidth);
  uint64_t above = overflow_;
  if (first < static_cast<double>(bins_.size()))
    for (size_t i = first < 0.0 ? 0 : static_cast<size_t>(first); i < bins_.size(); ++i) above += bins_[i];
  return static_cast<double>(above) / static_cast<double>(samples_);
}

std::vector<uint32_t> trianglesNear(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& positions,
                                    const std::vector<drape_vec3>& near, float radius, float min_edge) {
  std::vector<uint32_t> out;
  if (!(radius > 0.0f) || near.empty()) return out;
  // Cells of side `radius`: a point within radius of p lies in p's cell or one of its 26 neighbours.
  auto cellOf = [&](float v) { return static_cast<int64_t>(std::floor(v / radius)); };
  auto key = [](int64_t x, int64_t y, int64_t z) {
    return (static_cast<uint64_t>(x & 0x1fffff) << 42) | (static_cast<uint64_t>(y & 0x1fffff) << 21) |
           static_cast<uint64_t>(z & 0x1fffff);
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  for (uint32_t i = 0; i < near.size(); ++i) {
    const drape_vec3& q = near[i];
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) continue;
    grid[key(cellOf(q.x), cellOf(q.y), cellOf(q.z))].push_back(i);
  }
  const float r2 = radius * radius;
  std::vector<char> close(positions.size(), 0);
  for (size_t v = 0; v < positions.size(); ++v) {
    const drape_vec3& p = positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const int64_t cx = cellOf(p.x), cy = cellOf(p.y), cz = cellOf(p.z);
    for (int64_t dx = -1; dx <= 1 && !close[v]; ++dx)
      for (int64_t dy = -1; dy <= 1 && !close[v]; ++dy)
        for (int64_t dz = -1; dz <= 1 && !close[v]; ++dz) {
          const auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (uint32_t i : it->second) {
            const float ex = near[i].x - p.x, ey = near[i].y - p.y, ez = near[i].z - p.z;
            if (ex * ex + ey * ey + ez * ez <= r2) {
              close[v] = 1;
              break;
            }
          }
        }
  }
  auto length = [&](uint32_t a, uint32_t b) {
    const double dx = static_cast<double>(positions[a].x) - positions[b].x,
                 dy = static_cast<double>(positions[a].y) - positions[b].y,
                 dz = static_cast<double>(positions[a].z) - positions[b].z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  };
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a >= positions.size() || b >= positions.size() || c >= positions.size()) continue;
    if (!close[a] || !close[b] || !close[c]) continue;
    if (!(length(a, b) >= min_edge && length(b, c) >= min_edge && length(c, a) >= min_edge)) continue;
    out.insert(out.end(), {a, b, c});
  }
  return out;
}

}  // namespace replay
