#include "render.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace replay {

// Colours (sRGB 0..1): a light grey-beige mannequin and a blue T-shirt on a pale background.
const float kBodyColor[3] = {0.87f, 0.78f, 0.70f};
const float kGarmentColor[3] = {0.16f, 0.42f, 0.78f};
const float kUnderColor[3] = {0.16f, 0.17f, 0.22f};  // dark charcoal: trousers under a blue shirt
const uint8_t kBackground[3] = {236, 239, 243};

namespace {

constexpr float kAmbient = 0.22f;      // light that reaches surfaces facing away from the head light
constexpr float kNear = 0.05f;         // metres; triangles closer to the camera are skipped
constexpr float kOutlineDepth = 0.04f; // metres of depth jump that draw an outline
constexpr float kOutlineDarken = 0.35f;
constexpr float kFrameMargin = 0.08f;  // each side of the framed box
constexpr float kMinDistance = 2.5f;   // metres from the camera to the framed box's centre

void sub(const drape_vec3& a, const float b[3], float out[3]) {
  out[0] = a.x - b[0];
  out[1] = a.y - b[1];
  out[2] = a.z - b[2];
}

// Camera-space coordinates: right (in the picture), up, depth (along the view direction).
void toCamera(View view, const float d[3], float& right, float& up, float& depth) {
  up = d[1];
  if (view == View::Sensor) {
    right = d[0];   // mirrored: +X (the person's right) to the right of the picture
    depth = d[2];
  } else {
    right = -d[2];  // looking along -X: towards the sensor (-Z) is the right of the picture
    depth = -d[0];
  }
}

// 5x7 glyphs, rows top to bottom, '#' = ink.
struct Glyph {
  char c;
  const char* rows[7];
};
const Glyph kFont[] = {
    {'A', {" ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
    {'B', {"#### ", "#   #", "#   #", "#### ", "#   #", "#   #", "#### "}},
    {'C', {" ### ", "#   #", "#    ", "#    ", "#    ", "#   #", " ### "}},
    {'D', {"#### ", "#   #", "#   #", "#   #", "#   #", "#   #", "#### "}},
    {'E', {"#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#####"}},
    {'F', {"#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#    "}},
    {'G', {" ### ", "#   #", "#    ", "# ###", "#   #", "#   #", " ####"}},
    {'H', {"#   #", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
    {'I', {" ### ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'J', {"  ###", "   # ", "   # ", "   # ", "   # ", "#  # ", " ##  "}},
    {'K', {"#   #", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "#   #"}},
    {'L', {"#    ", "#    ", "#    ", "#    ", "#    ", "#    ", "#####"}},
    {'M', {"#   #", "## ##", "# # #", "# # #", "#   #", "#   #", "#   #"}},
    {'N', {"#   #", "#   #", "##  #", "# # #", "#  ##", "#   #", "#   #"}},
    {'O', {" ### ", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "}},
    {'P', {"#### ", "#   #", "#   #", "#### ", "#    ", "#    ", "#    "}},
    {'Q', {" ### ", "#   #", "#   #", "#   #", "# # #", "#  # ", " ## #"}},
    {'R', {"#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #"}},
    {'S', {" ####", "#    ", "#    ", " ### ", "    #", "    #", "#### "}},
    {'T', {"#####", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  "}},
    {'U', {"#   #", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "}},
    {'V', {"#   #", "#   #", "#   #", "#   #", "#   #", " # # ", "  #  "}},
    {'W', {"#   #", "#   #", "#   #", "# # #", "# # #", "# # #", " # # "}},
    {'X', {"#   #", "#   #", " # # ", "  #  ", " # # ", "#   #", "#   #"}},
    {'Y', {"#   #", "#   #", " # # ", "  #  ", "  #  ", "  #  ", "  #  "}},
    {'Z', {"#####", "    #", "   # ", "  #  ", " #   ", "#    ", "#####"}},
    {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
    {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
    {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "}},
    {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
    {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
    {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "}},
    {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
    {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
    {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "}},
    {'.', {"     ", "     ", "     ", "     ", "     ", " ##  ", " ##  "}},
    {',', {"     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   "}},
    {':', {"     ", " ##  ", " ##  ", "     ", " ##  ", " ##  ", "     "}},
    {'(', {"   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # "}},
    {')', {" #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   "}},
    {'/', {"     ", "    #", "   # ", "  #  ", " #   ", "#    ", "     "}},
    {'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     "}},
    {'=', {"     ", "     ", "#####", "     ", "#####", "     ", "     "}},
    {'_', {"     ", "     ", "     ", "     ", "     ", "     ", "#####"}},
    {'%', {"##   ", "##  #", "   # ", "  #  ", " #   ", "#  ##", "   ##"}},
};

const Glyph* findGlyph(char c) {
  c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;
}

}  // namespace

void Image::resize(int w, int h, const uint8_t fill[3]) {
  width = w;
  height = h;
  rgb.resize(static_cast<size_t>(w) * static_cast<size_t>(h) * 3);
  for (size_t i = 0; i < rgb.size(); i += 3) {
    rgb[i] = fill[0];
    rgb[i + 1] = fill[1];
    rgb[i + 2] = fill[2];
  }
}

Bounds boundsOf(const std::vector<drape_vec3>& positions) {
  Bounds b;
  for (const drape_vec3& p : positions) {
    const float v[3] = {p.x, p.y, p.z};
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) continue;
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = b.valid ? std::min(b.lo[k], v[k]) : v[k];
      b.hi[k] = b.valid ? std::max(b.hi[k], v[k]) : v[k];
    }
    b.valid = true;
  }
  return b;
}

const char* viewLabel(View view) {
  return view == View::Sensor ? "SENSOR VIEW (MIRRORED)" : "SIDE VIEW (FROM THE RIGHT)";
}

ViewCamera frameView(View view, const Bounds& body, int width, int height) {
  ViewCamera cam;
  cam.view = view;
  cam.width = width;
  cam.height = height;
  float c[3] = {0.0f, 0.9f, 2.5f}, size[3] = {0.6f, 1.7f, 0.4f};
  if (body.valid)
    for (int k = 0; k < 3; ++k) {
      c[k] = 0.5f * (body.lo[k] + body.hi[k]);
      size[k] = std::max(body.hi[k] - body.lo[k], 0.05f);
    }
  // The same box for both views (same scale): as wide as the body is tall at least, so that a
  // raised arm stays in the picture.
  const float box_h = size[1] * (1.0f + 2.0f * kFrameMargin);
  const float box_w = std::max({size[0], size[1], size[2]}) * (1.0f + 2.0f * kFrameMargin);

  // The sensor sits at the origin when the person is in front of it (Kinect space); otherwise
  // (e.g. a BVH take centred on the origin) the camera backs off along -Z.
  float eye_z = std::min(0.0f, c[2] - kMinDistance);
  const float distance = c[2] - eye_z;
  if (view == View::Sensor) {
    cam.eye[0] = 0.0f;
    cam.eye[1] = 0.0f;
    cam.eye[2] = eye_z;
  } else {
    cam.eye[0] = c[0] + distance;
    cam.eye[1] = c[1];
    cam.eye[2] = c[2];
  }
  cam.focal_px = std::min(static_cast<float>(width) * distance / box_w, static_cast<float>(height) * distance / box_h);
  float d[3] = {c[0] - cam.eye[0], c[1] - cam.eye[1], c[2] - cam.eye[2]};
  float right = 0, up = 0, depth = 1;
  toCamera(view, d, right, up, depth);
  cam.u0 = 0.5f * static_cast<float>(width) - cam.focal_px * right / depth;
  cam.v0 = 0.5f * static_cast<float>(height) + cam.focal_px * up / depth;
  return cam;
}

void Rasterizer::render(const ViewCamera& cam, const std::vector<MeshRef>& meshes, Image& out, int ss) {
  ss = std::max(1, ss);
  const int W = cam.width * ss, H = cam.height * ss;
  const size_t n = static_cast<size_t>(W) * static_cast<size_t>(H);
  inv_z_.assign(n, 0.0f);
  shade_.assign(n, 0.0f);
  mesh_.assign(n, 0);
  const float f = cam.focal_px * static_cast<float>(ss);
  const float u0 = cam.u0 * static_cast<float>(ss), v0 = cam.v0 * static_cast<float>(ss);

  for (size_t m = 0; m < meshes.size() && m < 254; ++m) {
    const MeshRef& mesh = meshes[m];
    if (!mesh.positions || !mesh.indices || mesh.vertex_count == 0) continue;
    // Vertex normals: the library's, or area-weighted face normals summed per vertex.
    const drape_vec3* normals = mesh.normals;
    if (!normals) {
      face_normals_.assign(mesh.vertex_count, drape_vec3{0, 0, 0});
      for (uint32_t t = 0; t + 2 < mesh.index_count; t += 3) {
        const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        if (a >= mesh.vertex_count || b >= mesh.vertex_count || c >= mesh.vertex_count) continue;
        const drape_vec3 &p0 = mesh.positions[a], &p1 = mesh.positions[b], &p2 = mesh.positions[c];
        const float e1[3] = {p1.x - p0.x, p1.y - p0.y, p1.z - p0.z}, e2[3] = {p2.x - p0.x, p2.y - p0.y, p2.z - p0.z};
        const drape_vec3 fn{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (uint32_t v : {a, b, c}) {
          face_normals_[v].x += fn.x;
          face_normals_[v].y += fn.y;
          face_normals_[v].z += fn.z;
        }
      }
      normals = face_normals_.data();
    }
    // Project the vertices and light them (Gouraud): a head light at the camera, both sides lit.
    projected_.resize(mesh.vertex_count);
    for (uint32_t v = 0; v < mesh.vertex_count; ++v) {
      Projected& pr = projected_[v];
      float d[3];
      sub(mesh.positions[v], cam.eye, d);
      float right = 0, up = 0, depth = 0;
      toCamera(cam.view, d, right, up, depth);
      pr.ok = std::isfinite(right) && std::isfinite(up) && std::isfinite(depth) && depth > kNear;
      if (!pr.ok) continue;
      pr.inv_z = 1.0f / depth;
      pr.x = u0 + f * right * pr.inv_z;
      pr.y = v0 - f * up * pr.inv_z;
      const drape_vec3& nv = normals[v];
      const float nn = std::sqrt(nv.x * nv.x + nv.y * nv.y + nv.z * nv.z);
      const float dd = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      float lambert = 0.0f;
      if (nn > 0.0f && dd > 0.0f && std::isfinite(nn))
        lambert = std::fabs(nv.x * d[0] + nv.y * d[1] + nv.z * d[2]) / (nn * dd);
      pr.shade = kAmbient + (1.0f - kAmbient) * std::min(lambert, 1.0f);
    }
    const uint8_t id = static_cast<uint8_t>(m + 1);
    for (uint32_t t = 0; t + 2 < mesh.index_count; t += 3) {
      const uint32_t ia = mesh.indices[t], ib = mesh.indices[t + 1], ic = mesh.indices[t + 2];
      if (ia >= mesh.vertex_count || ib >= mesh.vertex_count || ic >= mesh.vertex_count) continue;
      const Projected &a = projected_[ia], &b = projected_[ib], &c = projected_[ic];
      if (!a.ok || !b.ok || !c.ok) continue;
      const float area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      if (!(std::fabs(area) > 1e-12f)) continue;
      const float inv_area = 1.0f / area;  // the sign handles both windings (both sides drawn)
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
      const int x1 = std::min(W - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
      const int y1 = std::min(H - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
      for (int y = y0; y <= y1; ++y) {
        const float py = static_cast<float>(y) + 0.5f;
        for (int x = x0; x <= x1; ++x) {
          const float px = static_cast<float>(x) + 0.5f;
          const float w0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) * inv_area;
          const float w1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) * inv_area;
          const float w2 = 1.0f - w0 - w1;
          if (w0 < 0.0f || w1 < 0.0f || w2 < 0.0f) continue;
          const float iz = w0 * a.inv_z + w1 * b.inv_z + w2 * c.inv_z;
          const size_t k = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
          if (iz <= inv_z_[k]) continue;
          inv_z_[k] = iz;
          shade_[k] = w0 * a.shade + w1 * b.shade + w2 * c.shade;
          mesh_[k] = id;
        }
      }
    }
  }

  // Resolve: colour, outline (on the nearer side of a depth or material edge), then average the
  // ss x ss samples of each output pixel.
  out.resize(cam.width, cam.height, kBackground);
  std::vector<float> acc(static_cast<size_t>(cam.width) * 3);
  const float bg[3] = {kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f};
  const float norm = 1.0f / static_cast<float>(ss * ss);
  for (int oy = 0; oy < cam.height; ++oy) {
    std::fill(acc.begin(), acc.end(), 0.0f);
    for (int sy = 0; sy < ss; ++sy) {
      const int y = oy * ss + sy;
      for (int x = 0; x < W; ++x) {
        const size_t k = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
        float rgb[3] = {bg[0], bg[1], bg[2]};
        const uint8_t id = mesh_[k];
        if (id != 0) {
          const float* col = meshes[id - 1].color;
          float s = shade_[k];
          const float depth = 1.0f / inv_z_[k];
          const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
          for (int q = 0; q < 4; ++q) {
            if (nx[q] < 0 || ny[q] < 0 || nx[q] >= W || ny[q] >= H) continue;
            const size_t kq = static_cast<size_t>(ny[q]) * static_cast<size_t>(W) + static_cast<size_t>(nx[q]);
            const bool edge = mesh_[kq] == 0 || 1.0f / inv_z_[kq] - depth > kOutlineDepth ||
                              (mesh_[kq] != id && inv_z_[kq] < inv_z_[k]);
            if (edge) {
              s *= kOutlineDarken;
              break;
            }
          }
          for (int ch = 0; ch < 3; ++ch) rgb[ch] = col[ch] * s;
        }
        float* a = &acc[static_cast<size_t>(x / ss) * 3];
        a[0] += rgb[0];
        a[1] += rgb[1];
        a[2] += rgb[2];
      }
    }
    for (int ox = 0; ox < cam.width; ++ox) {
      uint8_t* p = out.at(ox, oy);
      for (int ch = 0; ch < 3; ++ch) {
        const float v = acc[static_cast<size_t>(ox) * 3 + static_cast<size_t>(ch)] * norm;
        p[ch] = static_cast<uint8_t>(std::min(std::max(v, 0.0f), 1.0f) * 255.0f + 0.5f);
      }
    }
  }
}

void resizeImage(const Image& src, int width, int height, Image& dst) {
  dst.resize(width, height, kBackground);
  if (src.width <= 0 || src.height <= 0 || width <= 0 || height <= 0) return;
  const double sx = static_cast<double>(src.width) / width, sy = static_cast<double>(src.height) / height;
  for (int y = 0; y < height; ++y) {
    const int ya = static_cast<int>(std::floor(y * sy)), yb = std::max(ya + 1, static_cast<int>(std::ceil((y + 1) * sy)));
    for (int x = 0; x < width; ++x) {
      const int xa = static_cast<int>(std::floor(x * sx)), xb = std::max(xa + 1, static_cast<int>(std::ceil((x + 1) * sx)));
      unsigned sum[3] = {0, 0, 0}, count = 0;
      for (int v = ya; v < yb && v < src.height; ++v)
        for (int u = xa; u < xb && u < src.width; ++u) {
          const uint8_t* p = src.at(u, v);
          sum[0] += p[0];
          sum[1] += p[1];
          sum[2] += p[2];
          ++count;
        }
      uint8_t* q = dst.at(x, y);
      for (int ch = 0; ch < 3; ++ch) q[ch] = static_cast<uint8_t>(count ? (sum[ch] + count / 2) / count : 0);
    }
  }
}

void blit(const Image& src, Image& dst, int x, int y) {
  for (int v = 0; v < src.height; ++v) {
    const int ty = y + v;
    if (ty < 0 || ty >= dst.height) continue;
    for (int u = 0; u < src.width; ++u) {
      const int tx = x + u;
      if (tx < 0 || tx >= dst.width) continue;
      const uint8_t* p = src.at(u, v);
      uint8_t* q = dst.at(tx, ty);
      q[0] = p[0];
      q[1] = p[1];
      q[2] = p[2];
    }
  }
}

void fillRect(Image& img, int x, int y, int w, int h, const uint8_t color[3]) {
  for (int v = std::max(0, y); v < std::min(img.height, y + h); ++v)
    for (int u = std::max(0, x); u < std::min(img.width, x + w); ++u) {
      uint8_t* q = img.at(u, v);
      q[0] = color[0];
      q[1] = color[1];
      q[2] = color[2];
    }
}

int textWidth(const std::string& text, int scale) {
  return text.empty() ? 0 : static_cast<int>(text.size()) * 6 * scale - scale;
}

void drawText(Image& img, int x, int y, const std::string& text, int scale, const uint8_t color[3]) {
  for (size_t i = 0; i < text.size(); ++i) {
    const Glyph* g = findGlyph(text[i]);
    if (!g) continue;
    const int gx = x + static_cast<int>(i) * 6 * scale;
    for (int row = 0; row < 7; ++row)
      for (int col = 0; col < 5; ++col)
        if (g->rows[row][col] == '#') fillRect(img, gx + col * scale, y + row * scale, scale, scale, color);
  }
}

}  // namespace replay
