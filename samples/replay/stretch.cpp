#include "stretch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace replay {

namespace {
constexpr size_t kBins = static_cast<size_t>((StretchAccumulator::kHigh - StretchAccumulator::kLow) /
                                                 StretchAccumulator::kBinWidth +
                                             0.5);
}  // namespace

void StretchAccumulator::setMesh(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& rest) {
  std::vector<uint64_t> edges;
  edges.reserve(indices.size());
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = indices[t + static_cast<size_t>(e)], j = indices[t + static_cast<size_t>((e + 1) % 3)];
      if (i == j || i >= rest.size() || j >= rest.size()) continue;
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

}  // namespace replay
