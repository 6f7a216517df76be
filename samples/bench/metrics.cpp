#include "metrics.h"

#include "cloth/garment_openings.h"
#include "cloth/garment_topology.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace bench {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return kNaN;
  const double rank = std::ceil(p / 100.0 * static_cast<double>(v.size()));
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::max(rank, 1.0)) - 1);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

double median(const std::vector<double>& v) { return percentile(v, 50.0); }

double mean(const std::vector<double>& v) {
  if (v.empty()) return kNaN;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

double maximum(const std::vector<double>& v) { return v.empty() ? kNaN : *std::max_element(v.begin(), v.end()); }

bool BodySurface::set(const std::vector<drape_vec3>& positions, const std::vector<uint32_t>& indices) {
  scratch_.resize(positions.size());
  for (size_t i = 0; i < positions.size(); ++i)
    scratch_[i] = drape::Vec3(positions[i].x, positions[i].y, positions[i].z);
  return bvh_.build(scratch_, indices);  // a refit after the first frame (same topology)
}

double BodySurface::depthMm(const drape_vec3& v) const {
  // The library's measure (GarmentSim::measure): inside by the winding number.
  return static_cast<double>(bvh_.depthInside(drape::Vec3(v.x, v.y, v.z))) * 1000.0;
}

void PenetrationMeter::addFrame(const BodySurface& body, const drape_vec3* vertices, size_t count) {
  for (size_t i = 0; i < count; ++i) {
    const double depth = body.depthMm(vertices[i]);
    depth_mm_.push_back(depth);
    if (depth > 2.0) ++deep_;
    if (depth > 0.0) ++inside_;
  }
}

double PenetrationMeter::p99Mm() const { return percentile(depth_mm_, 99.0); }
double PenetrationMeter::maxMm() const { return maximum(depth_mm_); }
double PenetrationMeter::deeperThan2mmFraction() const {
  return depth_mm_.empty() ? kNaN : static_cast<double>(deep_) / static_cast<double>(depth_mm_.size());
}
double PenetrationMeter::insideFraction() const {
  return depth_mm_.empty() ? kNaN : static_cast<double>(inside_) / static_cast<double>(depth_mm_.size());
}

namespace {

drape::Vec3 v3(const drape_vec3& v) { return drape::Vec3(v.x, v.y, v.z); }

// The body parts of OpeningsMeter (metrics.h) from this frame's ellipsoids: spine, left arm, right
// arm, left leg, right leg.
void bodyParts(const std::vector<drape_ellipsoid>& ellipsoids, std::vector<std::vector<drape::Vec3>>& parts) {
  using drape::Vec3;
  constexpr float kSpineExtensionM = drape::GarmentOpenings::kSpineExtensionM;
  constexpr float kLegExtensionM = drape::GarmentOpenings::kLegExtensionM;
  // Per chain: ring -> (sum of centres, count), and the ellipsoid of the highest ring (its end).
  std::map<int, std::pair<Vec3, int>> rings[6];
  const drape_ellipsoid* last[6] = {};
  for (const drape_ellipsoid& e : ellipsoids) {
    if (e.chain < 0 || e.chain > 5) continue;
    auto& r = rings[e.chain][e.ring];
    if (r.second == 0) r.first = Vec3::Zero();
    r.first += v3(e.centre);
    ++r.second;
    if (!last[e.chain] || e.ring >= last[e.chain]->ring) last[e.chain] = &e;
  }
  auto centres = [&](int chain) {
    std::vector<Vec3> c;
    for (const auto& [ring, sum] : rings[chain]) c.push_back(sum.first / static_cast<float>(sum.second));
    return c;
  };
  // On past the last centre by the last ellipsoid's half-length along its bone, away from the part.
  auto toTip = [&](int chain, std::vector<Vec3>& line) {
    if (line.size() < 2 || !last[chain]) return;
    Vec3 dir = v3(last[chain]->axis_y);
    if (dir.dot(line.back() - line[line.size() - 2]) < 0.0f) dir = -dir;
    line.push_back(v3(last[chain]->centre) + last[chain]->radii.y * dir);
  };
  parts.assign(5, {});
  std::vector<Vec3>& spine = parts[0];
  spine = centres(0);
  const std::vector<Vec3> head = centres(1);
  spine.insert(spine.end(), head.begin(), head.end());
  if (spine.size() >= 2) {
    const Vec3 down = (spine[0] - spine[1]).normalized();
    spine.insert(spine.begin(), spine[0] + kSpineExtensionM * down);
  }
  toTip(1, spine);
  for (int chain = 2; chain <= 5; ++chain) {
    std::vector<Vec3>& line = parts[static_cast<size_t>(chain - 1)];
    line = centres(chain);
    if (chain >= 4 && line.size() >= 2) line.insert(line.begin(), line[0] + kLegExtensionM * (line[0] - line[1]).normalized());
    toTip(chain, line);
  }
}

}  // namespace

void OpeningsMeter::bind(const std::vector<uint32_t>& indices, const drape_vec3* x, size_t n,
                         const std::vector<drape_ellipsoid>& ellipsoids) {
  openings_.clear();
  bodyParts(ellipsoids, parts_);
  for (std::vector<uint32_t>& loop : drape::boundaryLoops(indices, n)) {
    loop_.clear();
    for (uint32_t v : loop) loop_.push_back(v3(x[v]));
    float best = 0.0f;
    size_t best_part = 0;
    for (size_t p = 0; p < parts_.size(); ++p) {
      const float linking = drape::loopLinking(loop_, parts_[p]);
      if (std::fabs(linking) > std::fabs(best)) best = linking, best_part = p;
    }
    if (std::fabs(best) < drape::GarmentOpenings::kBindLinking) continue;
    openings_.push_back({std::move(loop), best_part, best > 0.0f ? 1 : -1});
  }
}

void OpeningsMeter::addFrame(const drape_vec3* x, const std::vector<drape_ellipsoid>& ellipsoids) {
  bodyParts(ellipsoids, parts_);
  bool off = false;
  for (const Opening& o : openings_) {
    loop_.clear();
    for (uint32_t v : o.loop) loop_.push_back(v3(x[v]));
    off = off || static_cast<float>(o.sign) * drape::loopLinking(loop_, parts_[o.part]) < drape::GarmentOpenings::kOffLinking;
  }
  ++frames_;
  off_frames_ += off ? 1 : 0;
}

double OpeningsMeter::offFraction() const {
  return frames_ == 0 ? kNaN : static_cast<double>(off_frames_) / static_cast<double>(frames_);
}

void StretchMeter::setMesh(const std::vector<uint32_t>& indices, const std::vector<drape_vec3>& rest) {
  std::map<std::pair<uint32_t, uint32_t>, bool> seen;
  a_.clear();
  b_.clear();
  rest_.clear();
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      uint32_t i = indices[t + e], j = indices[t + (e + 1) % 3];
      if (i > j) std::swap(i, j);
      if (!seen.emplace(std::make_pair(i, j), true).second) continue;
      const double dx = rest[i].x - rest[j].x, dy = rest[i].y - rest[j].y, dz = rest[i].z - rest[j].z;
      const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
      if (!(len > 0.0)) continue;  // a zero-length rest edge has no stretch ratio
      a_.push_back(i);
      b_.push_back(j);
      rest_.push_back(len);
    }
  }
}

void StretchMeter::setRest(const std::vector<drape_vec3>& rest) {
  for (size_t k = 0; k < a_.size(); ++k) {
    const drape_vec3& p = rest[a_[k]];
    const drape_vec3& q = rest[b_[k]];
    const double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
    const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (len > 0.0) rest_[k] = len;
  }
}

void StretchMeter::addFrame(const drape_vec3* x) {
  for (size_t k = 0; k < a_.size(); ++k) {
    const drape_vec3& p = x[a_[k]];
    const drape_vec3& q = x[b_[k]];
    const double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
    samples_.push_back(std::sqrt(dx * dx + dy * dy + dz * dz) / rest_[k] - 1.0);
  }
}

uint32_t countInsideEllipsoids(const drape_vec3* v, size_t count, const std::vector<uint8_t>& skip,
                               const std::vector<drape_ellipsoid>& ellipsoids) {
  constexpr float kInsideTol = 1e-4f;  // 0.1 mm along the ray from the centre, as the library
  uint32_t inside = 0;
  for (size_t i = 0; i < count; ++i) {
    if (i < skip.size() && skip[i]) continue;
    for (const drape_ellipsoid& e : ellipsoids) {
      const float px = v[i].x - e.centre.x, py = v[i].y - e.centre.y, pz = v[i].z - e.centre.z;
      const float ux = (px * e.axis_x.x + py * e.axis_x.y + pz * e.axis_x.z) / e.radii.x;
      const float uy = (px * e.axis_y.x + py * e.axis_y.y + pz * e.axis_y.z) / e.radii.y;
      const float uz = (px * e.axis_z.x + py * e.axis_z.y + pz * e.axis_z.z) / e.radii.z;
      const float r = std::sqrt(ux * ux + uy * uy + uz * uz);
      const float dist = std::sqrt(px * px + py * py + pz * pz);
      if (r < 1.0f && (1.0f - r) * dist > kInsideTol * std::max(r, 1e-6f)) {
        ++inside;
        break;
      }
    }
  }
  return inside;
}

void DeviationMeter::addFrame(const drape_vec3* run, const drape_vec3* ref, size_t count) {
  if (count == 0) return;
  double sum2 = 0.0, worst = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const double dx = run[i].x - ref[i].x, dy = run[i].y - ref[i].y, dz = run[i].z - ref[i].z;
    const double d2 = dx * dx + dy * dy + dz * dz;
    sum2 += d2;
    worst = std::max(worst, d2);
  }
  rms_mm_.push_back(1000.0 * std::sqrt(sum2 / static_cast<double>(count)));
  max_mm_.push_back(1000.0 * std::sqrt(worst));
}

}  // namespace bench
