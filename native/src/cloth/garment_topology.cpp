#include "cloth/garment_topology.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

namespace drape {
namespace {

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

void addConstraint(DistanceConstraints& c, uint32_t a, uint32_t b, float rest) {
  c.a.push_back(a);
  c.b.push_back(b);
  c.rest.push_back(rest);
}

struct EdgeUse {
  uint64_t key;       // (min << 32) | max
  uint32_t triangle;  // triangle index
  uint32_t opposite;  // the triangle's third vertex
};

}  // namespace

void colourConstraints(DistanceConstraints& c, size_t particle_count, bool colour_b) {
  const size_t n = c.size();
  std::vector<std::vector<uint64_t>> used(particle_count);
  std::vector<uint32_t> colour(n, 0);
  uint32_t colours = 0;
  for (size_t k = 0; k < n; ++k) {
    std::vector<uint64_t>& ua = used[c.a[k]];
    std::vector<uint64_t>* ub = colour_b ? &used[c.b[k]] : nullptr;
    uint32_t chosen = 0;
    for (size_t w = 0;; ++w) {
      uint64_t taken = w < ua.size() ? ua[w] : 0;
      if (ub != nullptr && w < ub->size()) taken |= (*ub)[w];
      if (taken != ~uint64_t{0}) {
        uint32_t bit = 0;
        while ((taken >> bit) & 1u) ++bit;
        chosen = static_cast<uint32_t>(w * 64 + bit);
        break;
      }
    }
    const size_t word = chosen / 64;
    const uint64_t mask = uint64_t{1} << (chosen % 64);
    if (ua.size() <= word) ua.resize(word + 1, 0);
    ua[word] |= mask;
    if (ub != nullptr) {
      if (ub->size() <= word) ub->resize(word + 1, 0);
      (*ub)[word] |= mask;
    }
    colour[k] = chosen;
    colours = std::max(colours, chosen + 1);
  }
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t x, uint32_t y) { return colour[x] < colour[y]; });
  DistanceConstraints sorted;
  sorted.a.reserve(n);
  sorted.b.reserve(n);
  sorted.rest.reserve(n);
  sorted.colour_offsets.assign(colours + 1, 0);
  for (uint32_t k : order) {
    addConstraint(sorted, c.a[k], c.b[k], c.rest[k]);
    sorted.colour_offsets[colour[k] + 1]++;
  }
  for (uint32_t col = 0; col < colours; ++col)
    sorted.colour_offsets[col + 1] += sorted.colour_offsets[col];
  c = std::move(sorted);
}

bool buildGarmentTopology(const float* positions, size_t vertex_count, const uint32_t* indices,
                          size_t index_count, const TopologyParams& params, GarmentTopology& out,
                          std::string& error) {
  if (positions == nullptr || vertex_count == 0) {
    error = "garment mesh has no vertices";
    return false;
  }
  if (indices == nullptr || index_count == 0) {
    error = "garment mesh has no triangles";
    return false;
  }
  if (index_count % 3 != 0) {
    error = "garment index count " + std::to_string(index_count) + " is not a multiple of 3";
    return false;
  }
  if (vertex_count >= 0xffffffffu) {
    error = "garment mesh has too many vertices";
    return false;
  }
  if (!(params.area_density > 0.0f) || !std::isfinite(params.area_density)) {
    error = "area density must be positive and finite (kg/m^2)";
    return false;
  }
  if (params.max_tethers_per_particle < 0) {
    error = "max_tethers_per_particle must not be negative";
    return false;
  }
  GarmentTopology t;
  t.rest_positions.resize(vertex_count);
  for (size_t i = 0; i < vertex_count; ++i) {
    const Vec3 p(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
    if (!isFinite(p)) {
      error = "garment vertex " + std::to_string(i) + " has a non-finite position";
      return false;
    }
    t.rest_positions[i] = p;
  }
  const size_t triangle_count = index_count / 3;
  t.triangles.assign(indices, indices + index_count);
  t.mass.assign(vertex_count, 0.0f);
  std::vector<double> mass(vertex_count, 0.0);
  for (size_t f = 0; f < triangle_count; ++f) {
    const uint32_t i0 = indices[3 * f], i1 = indices[3 * f + 1], i2 = indices[3 * f + 2];
    if (i0 >= vertex_count || i1 >= vertex_count || i2 >= vertex_count) {
      error = "triangle " + std::to_string(f) + " has an index out of range (vertex count " +
              std::to_string(vertex_count) + ")";
      return false;
    }
    if (i0 == i1 || i1 == i2 || i2 == i0) {
      error = "triangle " + std::to_string(f) + " is degenerate (repeated index)";
      return false;
    }
    const Vec3& p0 = t.rest_positions[i0];
    const double area = 0.5 * static_cast<double>(
                                  (t.rest_positions[i1] - p0).cross(t.rest_positions[i2] - p0).norm());
    if (!(area >= 1e-12)) {
      error = "triangle " + std::to_string(f) + " is degenerate (area " + std::to_string(area) +
              " m^2)";
      return false;
    }
    const double third = area * static_cast<double>(params.area_density) / 3.0;
    mass[i0] += third;
    mass[i1] += third;
    mass[i2] += third;
  }
  for (size_t i = 0; i < vertex_count; ++i) {
    if (!(mass[i] > 0.0)) {
      error = "garment vertex " + std::to_string(i) + " belongs to no triangle";
      return false;
    }
    t.mass[i] = static_cast<float>(mass[i]);
  }
  t.pinned = params.pinned;
  std::sort(t.pinned.begin(), t.pinned.end());
  t.pinned.erase(std::unique(t.pinned.begin(), t.pinned.end()), t.pinned.end());
  for (uint32_t p : t.pinned) {
    if (p >= vertex_count) {
      error = "pinned vertex " + std::to_string(p) + " is out of range (vertex count " +
              std::to_string(vertex_count) + ")";
      return false;
    }
  }
  t.inverse_mass.resize(vertex_count);
  for (size_t i = 0; i < vertex_count; ++i) t.inverse_mass[i] = 1.0f / t.mass[i];
  for (uint32_t p : t.pinned) t.inverse_mass[p] = 0.0f;

  // Edges with their adjacent triangles, sorted by edge then triangle (deterministic).
  std::vector<EdgeUse> uses;
  uses.reserve(index_count);
  for (size_t f = 0; f < triangle_count; ++f) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = indices[3 * f + static_cast<size_t>(e)];
      const uint32_t j = indices[3 * f + static_cast<size_t>((e + 1) % 3)];
      const uint32_t o = indices[3 * f + static_cast<size_t>((e + 2) % 3)];
      const uint64_t key = (uint64_t{std::min(i, j)} << 32) | std::max(i, j);
      uses.push_back({key, static_cast<uint32_t>(f), o});
    }
  }
  std::stable_sort(uses.begin(), uses.end(),
                   [](const EdgeUse& x, const EdgeUse& y) { return x.key < y.key; });
  auto dist = [&](uint32_t i, uint32_t j) {
    return (t.rest_positions[i] - t.rest_positions[j]).norm();
  };
  // Whether edge (i, j) is the longest edge of triangle f (ties count as longest, 1e-6 relative).
  auto longest = [&](uint32_t f, uint32_t i, uint32_t j) {
    const float l = dist(i, j);
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = indices[3 * f + static_cast<size_t>(e)];
      const uint32_t b = indices[3 * f + static_cast<size_t>((e + 1) % 3)];
      if (dist(a, b) > l * (1.0f + 1e-6f)) return false;
    }
    return true;
  };
  for (size_t k = 0; k < uses.size();) {
    size_t end = k + 1;
    while (end < uses.size() && uses[end].key == uses[k].key) ++end;
    const uint32_t i = static_cast<uint32_t>(uses[k].key >> 32);
    const uint32_t j = static_cast<uint32_t>(uses[k].key & 0xffffffffu);
    addConstraint(t.stretch, i, j, dist(i, j));
    if (end - k == 2) {  // interior manifold edge; boundary and non-manifold edges get none
      const uint32_t o0 = uses[k].opposite, o1 = uses[k + 1].opposite;
      if (o0 != o1) {
        const bool diagonal = longest(uses[k].triangle, i, j) && longest(uses[k + 1].triangle, i, j);
        addConstraint(diagonal ? t.shear : t.bend, std::min(o0, o1), std::max(o0, o1),
                      dist(o0, o1));
      }
    }
    k = end;
  }

  // Tethers: nearest pinned particles (Euclidean, ties by index) in the same connected piece.
  if (params.max_tethers_per_particle > 0 && !t.pinned.empty()) {
    std::vector<uint32_t> parent(vertex_count);
    std::iota(parent.begin(), parent.end(), 0u);
    for (size_t k = 0; k < t.stretch.size(); ++k) {
      const uint32_t ra = findRoot(parent, t.stretch.a[k]), rb = findRoot(parent, t.stretch.b[k]);
      if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
    const size_t keep = static_cast<size_t>(params.max_tethers_per_particle);
    std::vector<std::pair<float, uint32_t>> candidates;
    for (uint32_t i = 0; i < vertex_count; ++i) {
      if (t.inverse_mass[i] == 0.0f) continue;
      candidates.clear();
      const uint32_t root = findRoot(parent, i);
      for (uint32_t p : t.pinned)
        if (findRoot(parent, p) == root) candidates.emplace_back(dist(i, p), p);
      const size_t n = std::min(keep, candidates.size());
      std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(n),
                        candidates.end());
      for (size_t c = 0; c < n; ++c)
        addConstraint(t.tether, i, candidates[c].second, candidates[c].first);
    }
  }

  colourConstraints(t.stretch, vertex_count, true);
  colourConstraints(t.shear, vertex_count, true);
  colourConstraints(t.bend, vertex_count, true);
  colourConstraints(t.tether, vertex_count, false);
  for (const std::vector<uint32_t>& loop : boundaryLoops(t.triangles, vertex_count))
    for (size_t k = 0; k < loop.size(); ++k) {
      const uint32_t i = loop[k], j = loop[(k + 1) % loop.size()];
      addConstraint(t.rims, std::min(i, j), std::max(i, j), dist(i, j));
    }
  colourConstraints(t.rims, vertex_count, true);
  out = std::move(t);
  error.clear();
  return true;
}

std::vector<std::vector<uint32_t>> boundaryLoops(const std::vector<uint32_t>& triangles, size_t vertex_count) {
  std::vector<uint64_t> keys;
  keys.reserve(triangles.size());
  for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
    if (triangles[t] >= vertex_count || triangles[t + 1] >= vertex_count || triangles[t + 2] >= vertex_count) continue;
    for (size_t k = 0; k < 3; ++k) {
      const uint64_t a = triangles[t + k], b = triangles[t + (k + 1) % 3];
      if (a != b) keys.push_back(std::min(a, b) << 32 | std::max(a, b));
    }
  }
  std::sort(keys.begin(), keys.end());
  std::vector<uint64_t> edges, ends;  // boundary edges; (vertex << 32 | edge id) for both ends
  for (size_t i = 0, j = 0; i < keys.size(); i = j) {
    while (j < keys.size() && keys[j] == keys[i]) ++j;
    if (j - i > 1) continue;
    ends.push_back((keys[i] >> 32) << 32 | edges.size());
    ends.push_back((keys[i] & 0xffffffffu) << 32 | edges.size());
    edges.push_back(keys[i]);
  }
  std::sort(ends.begin(), ends.end());
  std::vector<char> used(edges.size(), 0);
  const auto nextEdge = [&](uint64_t v) -> size_t {
    for (auto it = std::lower_bound(ends.begin(), ends.end(), v << 32); it != ends.end() && (*it >> 32) == v; ++it) {
      if (!used[*it & 0xffffffffu]) return *it & 0xffffffffu;
    }
    return edges.size();
  };
  std::vector<std::vector<uint32_t>> loops;
  std::vector<uint32_t> loop;
  for (size_t h = 0; h < edges.size(); ++h) {
    if (used[h]) continue;
    used[h] = 1;
    const uint64_t start = edges[h] >> 32;
    uint64_t cur = edges[h] & 0xffffffffu;
    loop.assign(1, static_cast<uint32_t>(start));
    while (cur != start) {
      loop.push_back(static_cast<uint32_t>(cur));
      const size_t e = nextEdge(cur);
      if (e == edges.size()) break;  // an open chain (odd-degree vertex): not a loop
      used[e] = 1;
      cur = (edges[e] >> 32) == cur ? edges[e] & 0xffffffffu : edges[e] >> 32;
    }
    if (cur == start && loop.size() >= 3) loops.push_back(loop);
  }
  return loops;
}

void makeClothGrid(int nx, int ny, float width, float height, const Vec3& origin, const Vec3& u,
                   const Vec3& v, std::vector<float>& positions, std::vector<uint32_t>& indices) {
  positions.clear();
  indices.clear();
  if (nx < 2 || ny < 2) return;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const Vec3 p = origin + u * (width * static_cast<float>(i) / static_cast<float>(nx - 1)) +
                     v * (height * static_cast<float>(j) / static_cast<float>(ny - 1));
      positions.insert(positions.end(), {p.x(), p.y(), p.z()});
    }
  }
  auto id = [nx](int i, int j) { return static_cast<uint32_t>(j * nx + i); };
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      indices.insert(indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      indices.insert(indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
}

}  // namespace drape
