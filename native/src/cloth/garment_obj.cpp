// OBJ garments (garment_obj.h): a strict, allocation-light OBJ reader and the ring-space
// retargeting fit. Method and measurements: docs/garment-obj.md.
#include "cloth/garment_obj.h"

#include "body/body_shape.h"
#include "cloth/garment_topology.h"
#include "cloth/ring_skin.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string_view>

namespace drape {

namespace {

// ---- Parsing --------------------------------------------------------------------------------

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// from_chars rejects a leading '+', which some exporters write.
std::string_view dropPlus(std::string_view t) {
  return (t.size() > 1 && t[0] == '+' && t[1] != '-') ? t.substr(1) : t;
}

// Parsed as double so that values beyond float's range are caught here rather than becoming inf.
bool toFloat(std::string_view t, float& v, bool& finite) {
  t = dropPlus(t);
  double d = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), d);
  if (t.empty() || r.ptr != t.data() + t.size()) return false;
  const bool underflow = r.ec == std::errc::result_out_of_range &&
                         (t.find("e-") != std::string_view::npos || t.find("E-") != std::string_view::npos);
  if (underflow) d = 0.0;
  finite = (r.ec == std::errc() || underflow) && std::isfinite(d) && std::fabs(d) <= std::numeric_limits<float>::max();
  v = finite ? static_cast<float>(d) : 0.0f;
  return r.ec == std::errc() || r.ec == std::errc::result_out_of_range;
}

bool toInt(std::string_view t, long long& v) {
  t = dropPlus(t);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// The vertex index of one face corner "v", "v/vt", "v//vn" or "v/vt/vn"; vt and vn are checked for
// form only (they are not used).
bool cornerIndex(std::string_view tok, long long& v) {
  size_t parts = 0, start = 0;
  for (size_t i = 0; i <= tok.size(); ++i) {
    if (i < tok.size() && tok[i] != '/') continue;
    const std::string_view part = tok.substr(start, i - start);
    long long value = 0;
    if (parts == 0 && !toInt(part, v)) return false;
    if (parts > 0 && !part.empty() && !toInt(part, value)) return false;
    if (++parts > 3) return false;
    start = i + 1;
  }
  return true;
}

}  // namespace

bool parseObj(const char* text, size_t size, ObjMesh& out, std::string& err) {
  size_t line = 0;
  const auto fail = [&](size_t ln, const std::string& what) {
    err = ln ? "line " + std::to_string(ln) + ": " + what : what;
    return false;
  };
  if (!text && size > 0) return fail(0, "OBJ text is null");
  std::vector<Vec3> positions;
  std::vector<uint32_t> tris, face, sorted;
  std::vector<std::string_view> toks;
  struct Face { size_t tri_begin, line; };  // positive indices are checked once every v is read
  std::vector<Face> faces;
  for (size_t pos = 0; pos < size;) {
    const char* b = text + pos;
    const char* nl = static_cast<const char*>(std::memchr(b, '\n', size - pos));
    const char* e = nl ? nl : text + size;
    pos = static_cast<size_t>(e - text) + 1;
    ++line;
    if (const char* hash = static_cast<const char*>(std::memchr(b, '#', static_cast<size_t>(e - b)))) e = hash;
    toks.clear();
    for (const char* c = b; c < e;) {
      while (c < e && isBlank(*c)) ++c;
      const char* s = c;
      while (c < e && !isBlank(*c)) ++c;
      if (c > s) toks.emplace_back(s, static_cast<size_t>(c - s));
    }
    if (toks.empty()) continue;
    const std::string_view kw = toks[0];
    if (kw == "v") {
      if (toks.size() < 4) return fail(line, "vertex needs x y z");
      float xyz[3] = {0.0f, 0.0f, 0.0f};
      for (size_t i = 1; i < toks.size(); ++i) {
        float value = 0.0f;
        bool finite = true;
        if (!toFloat(toks[i], value, finite)) return fail(line, "malformed number '" + std::string(toks[i]) + "'");
        if (i <= 3 && !finite) return fail(line, "non-finite coordinate '" + std::string(toks[i]) + "'");
        if (i <= 3) xyz[i - 1] = value;
      }
      positions.emplace_back(xyz[0], xyz[1], xyz[2]);
    } else if (kw == "f") {
      face.clear();
      const long long n = static_cast<long long>(positions.size());
      for (size_t i = 1; i < toks.size(); ++i) {
        long long v = 0;
        if (!cornerIndex(toks[i], v)) return fail(line, "malformed face corner '" + std::string(toks[i]) + "'");
        if (v == 0) return fail(line, "vertex index 0 (OBJ indices start at 1)");
        if (v < 0 && n + v < 0) {
          return fail(line, "relative vertex index " + std::to_string(v) + " out of range (" + std::to_string(n) +
                                " vertices so far)");
        }
        if (v > 0xffffffffll) return fail(line, "vertex index " + std::to_string(v) + " out of range");
        face.push_back(static_cast<uint32_t>(v < 0 ? n + v : v - 1));
      }
      if (face.size() < 3) {
        return fail(line, "face with " + std::to_string(face.size()) + " vertices (needs at least 3)");
      }
      sorted = face;
      std::sort(sorted.begin(), sorted.end());
      if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
        return fail(line, "degenerate face (a vertex repeated)");
      }
      // Fanned from the first corner; a quad's diagonal is chosen below, once every position is
      // known (a face may name vertices defined after it).
      faces.push_back({tris.size(), line});
      for (size_t i = 1; i + 1 < face.size(); ++i) tris.insert(tris.end(), {face[0], face[i], face[i + 1]});
    } else if (kw != "vt" && kw != "vn" && kw != "vp" && kw != "o" && kw != "g" && kw != "s" && kw != "l" &&
               kw != "p" && kw != "usemtl" && kw != "mtllib") {
      return fail(line, "unsupported statement '" + std::string(kw) + "'");
    }
  }
  if (faces.empty()) return fail(0, "no faces");
  const size_t nv = positions.size();
  for (size_t f = 0; f < faces.size(); ++f) {
    const size_t begin = faces[f].tri_begin, end = f + 1 < faces.size() ? faces[f + 1].tri_begin : tris.size();
    for (size_t i = begin; i < end; ++i) {
      if (tris[i] >= nv) {
        return fail(faces[f].line, "vertex index " + std::to_string(tris[i] + 1ull) + " out of range (" +
                                       std::to_string(nv) + " vertices)");
      }
    }
    uint32_t* q = &tris[begin];
    if (end - begin == 6 && (positions[q[1]] - positions[q[5]]).squaredNorm() <
                                (positions[q[0]] - positions[q[2]]).squaredNorm()) {
      const uint32_t alt[6] = {q[0], q[1], q[5], q[1], q[2], q[5]};  // quad a b c d split along b-d
      std::copy(alt, alt + 6, q);
    }
  }
  // Drop vertices no face uses (keeping the file's order) so every particle has mass.
  std::vector<uint32_t> remap(nv, 0);
  for (uint32_t i : tris) remap[i] = 1;
  ObjMesh m;
  for (size_t i = 0; i < nv; ++i) {
    if (remap[i]) {
      remap[i] = static_cast<uint32_t>(m.positions.size());
      m.positions.push_back(positions[i]);
    }
  }
  m.indices.reserve(tris.size());
  for (uint32_t i : tris) m.indices.push_back(remap[i]);
  out = std::move(m);
  return true;
}

bool readObjFile(const std::string& path, ObjMesh& out, std::string& err, bool* io_error) {
  if (io_error) *io_error = true;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    err = "cannot read '" + path + "': it is a directory";
    return false;
  }
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    err = "cannot open '" + path + "': " + std::strerror(errno);
    return false;
  }
  std::string text;
  try {
    text.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  } catch (const std::ios_base::failure&) {
    f.setstate(std::ios::badbit);
  }
  if (f.bad()) {
    err = "cannot read '" + path + "'";
    return false;
  }
  if (io_error) *io_error = false;
  if (parseObj(text.data(), text.size(), out, err)) return true;
  err = path + ": " + err;
  return false;
}

// ---- Fitting --------------------------------------------------------------------------------

namespace {

bool sameLayout(const BodyModel& a, const BodyModel& b) {
  if (a.stations().size() != b.stations().size()) return false;
  for (int c = 0; c < kChainCount; ++c) {
    const Chain ch = static_cast<Chain>(c);
    if (a.chainFirstRing(ch) != b.chainFirstRing(ch) || a.chainRingCount(ch) != b.chainRingCount(ch)) return false;
  }
  for (size_t i = 0; i < a.stations().size(); ++i) {
    if (a.stations()[i].u != b.stations()[i].u) return false;
  }
  return true;
}

bool checkFitParams(const ObjFitParams& p, ResolvedShape& shape, std::string& err) {
  const auto in = [](float v, float lo, float hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!in(p.unit_scale, 0.0f, 1000.0f)) {
    err = "unit_scale must be 0 (auto) or in (0, 1000] metres per unit";
  } else if (p.facing != ObjFacing::PlusZ && p.facing != ObjFacing::MinusZ) {
    err = "facing must be PlusZ or MinusZ";
  } else if (!in(p.source_floor_y, -100.0f, 100.0f) || !in(p.source_axis_z, -100.0f, 100.0f)) {
    err = "source_floor_y and source_axis_z must be finite metres within +-100";
  } else if (!in(p.source_arm_down_deg, 0.0f, 90.0f) || !in(p.source_elbow_flex_deg, 0.0f, 150.0f) ||
             !in(p.source_leg_spread_deg, -45.0f, 45.0f)) {
    err = "source pose: arm_down in [0, 90], elbow_flex in [0, 150], leg_spread in [-45, 45] degrees";
  } else if (!in(p.blend_m, 0.0f, 0.2f)) {
    err = "blend_m must be in [0, 0.2] m";
  } else {
    BodyShapeInput body;
    body.height_m = p.source_height_m;
    body.weight_kg = p.source_weight_kg;
    if (!validateShapeInput(body, err)) {
      err = "source body: " + err;
      return false;
    }
    shape = resolveShape(body);
    return true;
  }
  return false;
}

// The pose the garment was made on: restPose with the forearms bent forward (-Z) at the elbows
// and the legs turned outward about the hips in the frontal plane, segment lengths kept.
SkeletonPose sourcePose(const ResolvedShape& shape, const ObjFitParams& p) {
  SkeletonPose pose = restPose(shape, p.source_arm_down_deg);
  const auto P = [&](Joint j) -> Vec3& { return pose.position[idx(j)]; };
  const float flex = p.source_elbow_flex_deg * kPi / 180.0f;
  for (int side = 0; side < 2; ++side) {
    const bool L = side == 0;
    const Vec3 s = P(L ? Joint::ShoulderL : Joint::ShoulderR), e = P(L ? Joint::ElbowL : Joint::ElbowR);
    Vec3& w = P(L ? Joint::WristL : Joint::WristR);
    Vec3& h = P(L ? Joint::HandL : Joint::HandR);
    const float lw = (w - e).norm(), lh = (h - w).norm();
    const Vec3 dir = std::cos(flex) * (e - s).normalized() - std::sin(flex) * Vec3::UnitZ();
    w = e + lw * dir;
    h = w + lh * dir;
    const float a = (L ? -1.0f : 1.0f) * p.source_leg_spread_deg * kPi / 180.0f;  // left leg is -X
    const Mat3 R = Eigen::AngleAxisf(a, Vec3::UnitZ()).toRotationMatrix();
    const Vec3 hip = P(L ? Joint::HipL : Joint::HipR);
    const Joint leg[3] = {L ? Joint::KneeL : Joint::KneeR, L ? Joint::AnkleL : Joint::AnkleR,
                          L ? Joint::FootL : Joint::FootR};
    for (Joint j : leg) P(j) = hip + R * (P(j) - hip);
  }
  return pose;
}

// For each connected component, the loop to pin (empty when none): among the boundary loops
// (boundaryLoops, cloth/garment_topology.h: walked as an undirected graph, since the elegant suit's
// lapel has a flipped face beside a pinch vertex), the highest (mean source y) whose vertices are
// mostly bound to the Torso or Head chain and which winds once around that chain's axis.
std::vector<std::vector<uint32_t>> attachmentLoops(const std::vector<uint32_t>& I, const std::vector<Vec3>& src,
                                                   const std::vector<RingBinding>& primary) {
  const size_t nv = src.size();
  std::vector<uint32_t> parent(nv);
  for (uint32_t i = 0; i < nv; ++i) parent[i] = i;
  const auto find = [&](uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (size_t t = 0; t < I.size(); t += 3) {
    parent[find(I[t])] = find(I[t + 1]);
    parent[find(I[t + 1])] = find(I[t + 2]);
  }
  std::vector<std::vector<uint32_t>> chosen(nv);  // indexed by component root
  std::vector<float> chosenY(nv, -std::numeric_limits<float>::infinity());
  for (const std::vector<uint32_t>& loop : boundaryLoops(I, nv)) {
    size_t onTrunk = 0;
    float turn = 0.0f, meanY = 0.0f;
    for (size_t i = 0; i < loop.size(); ++i) {
      const RingBinding& a = primary[loop[i]];
      const RingBinding& b = primary[loop[(i + 1) % loop.size()]];
      onTrunk += a.chain == int(Chain::Torso) || a.chain == int(Chain::Head);
      float d = std::atan2(b.local.z(), b.local.x()) - std::atan2(a.local.z(), a.local.x());
      turn += d - 2.0f * kPi * std::round(d / (2.0f * kPi));
      meanY += src[loop[i]].y() / static_cast<float>(loop.size());
    }
    const uint32_t root = find(loop[0]);
    if (2 * onTrunk > loop.size() && std::fabs(turn) > kPi && meanY > chosenY[root]) {
      chosen[root] = loop;
      chosenY[root] = meanY;
    }
  }
  return chosen;
}

}  // namespace

bool placeObjOnSourceBody(const ObjMesh& mesh, const ObjFitParams& p, std::vector<Vec3>& out, std::string& err) {
  ResolvedShape shape;
  if (!checkFitParams(p, shape, err)) return false;
  const size_t nv = mesh.positions.size();
  if (nv == 0 || mesh.indices.empty() || mesh.indices.size() % 3 != 0 ||
      *std::max_element(mesh.indices.begin(), mesh.indices.end()) >= nv) {
    err = "mesh needs vertices and whole triangles with indices in range";
    return false;
  }
  std::vector<char> used(nv, 0);  // an unused vertex would be a particle without mass
  for (uint32_t i : mesh.indices) used[i] = 1;
  if (const auto it = std::find(used.begin(), used.end(), 0); it != used.end()) {
    err = "vertex " + std::to_string(it - used.begin()) + " is used by no triangle";
    return false;
  }
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Vec3& v : mesh.positions) {
    if (!isFinite(v)) {
      err = "non-finite vertex position";
      return false;
    }
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const float extent = (hi - lo).maxCoeff();
  if (!(extent > 0.0f)) {
    err = "all vertices coincide";
    return false;
  }
  float scale = p.unit_scale;
  for (float s : {1.0f, 0.1f, 0.01f, 0.001f}) {
    if (scale == 0.0f && extent * s <= 2.5f) scale = s;
  }
  if (scale == 0.0f) {
    err = "no unit brings the mesh's extent of " + std::to_string(extent) + " units under 2.5 m";
    return false;
  }
  // A half turn about Y, (x, z) -> (-x, -z), is a proper rotation: handedness and winding are kept.
  const float flip = p.facing == ObjFacing::PlusZ ? -1.0f : 1.0f;
  const Vec3 pelvis = restPose(shape).position[idx(Joint::Pelvis)];
  const Vec3 shift(pelvis.x(), -p.source_floor_y, pelvis.z() - flip * p.source_axis_z);
  std::vector<Vec3> placed(nv);
  for (size_t i = 0; i < nv; ++i) {
    const Vec3 v = mesh.positions[i] * scale;
    placed[i] = Vec3(flip * v.x(), v.y(), flip * v.z()) + shift;
  }
  out = std::move(placed);
  return true;
}

bool fitObjGarment(const ObjMesh& mesh, const ObjFitParams& p, const BodyModel& target, GarmentMesh& out,
                   std::string& err) {
  std::vector<Vec3> src;
  ResolvedShape shape;
  if (!placeObjOnSourceBody(mesh, p, src, err) || !checkFitParams(p, shape, err)) return false;
  for (const RingPose& r : target.rings()) {
    if (!isFinite(r.centre) || !r.frame.allFinite() || !(r.forward_m > 1e-4f) || !(r.side_m > 1e-4f)) {
      err = "target body has a non-finite or empty ring (update it with a pose first)";
      return false;
    }
  }
  // Bindings name rings by index, so the source body needs the target's ring layout. BodyModel
  // keeps its params private: recover rings_per_segment by matching the stations.
  BodyModelParams bp;
  bp.ring_points = target.ringPoints();
  bool matched = false;
  for (int e = 0; e <= 16 && !matched; ++e) {
    bp.rings_per_segment = e;
    matched = sameLayout(BodyModel(shape, bp), target);
  }
  if (!matched) {
    err = "target body's ring layout matches no BodyModelParams";
    return false;
  }
  BodyModel source(shape, bp);
  source.update(sourcePose(shape, p));
  const std::vector<RingPose>& T = target.rings();

  // The nearest segment (primary binding) decides attachments; the position blends every segment
  // nearly as near, each of which maps the vertex exactly onto itself on the source body.
  const size_t nv = src.size();
  GarmentMesh g;
  g.indices = mesh.indices;
  RingSkin skin;
  skin.bind(source, src, p.blend_m);
  skin.place(target, g.positions);
  for (const Vec3& x : g.positions) {
    if (!isFinite(x)) {
      err = "fit produced a non-finite position";
      return false;
    }
  }
  const std::vector<RingBinding>& primary = skin.primaries();
  std::vector<char> isPinned(nv, 0);
  for (const std::vector<uint32_t>& loop : attachmentLoops(mesh.indices, src, primary)) {
    for (uint32_t v : loop) {
      if (isPinned[v]) continue;
      isPinned[v] = 1;
      const int r = primary[v].t < 0.5f ? primary[v].r0 : primary[v].r0 + 1;
      g.pinned.push_back(v);
      g.pin_ring.push_back(r);
      g.pin_local.push_back(T[r].frame.transpose() * (g.positions[v] - T[r].centre));
    }
  }
  out = std::move(g);
  return true;
}

}  // namespace drape
