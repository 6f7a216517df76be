// A small software rasteriser for drape-replay's pictures: z-buffer, Gouraud-shaded Lambert with a
// head light (a light at the camera), both sides of every triangle lit (the garment is open cloth),
// 2x2 supersampling and a dark outline where depth or material jumps. No GPU, no dependencies.
//
// Two views of Kinect camera space (metres; +Y up, +Z from the sensor towards the person, +X to the
// sensor's left, which is the person's right when they face the sensor):
//   sensor  the camera at the origin looking along +Z, drawn mirrored (+X to the right of the
//           picture), the way the person would see themselves in a dressing-room mirror;
//   side    a camera to the person's right (at +X) looking along -X at the centre of the body's
//           first-frame bounding box: the person faces the right edge of the picture.
// Both are framed on the body's bounding box of the first frame, at the same scale.
#pragma once

#include <drape/drape.h>

#include <cstdint>
#include <string>
#include <vector>

namespace replay {

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // width * height * 3, rows top to bottom

  void resize(int w, int h, const uint8_t fill[3]);
  uint8_t* at(int x, int y) { return &rgb[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3]; }
  const uint8_t* at(int x, int y) const {
    return &rgb[(static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 3];
  }
};

struct Bounds {
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool valid = false;
};
// Bounding box of the finite positions (valid false when there are none).
Bounds boundsOf(const std::vector<drape_vec3>& positions);

enum class View { Sensor, Side };
const char* viewLabel(View view);  // "SENSOR VIEW (MIRRORED)", "SIDE VIEW (FROM THE RIGHT)"

// A pinhole camera in Kinect space, with its picture size.
struct ViewCamera {
  View view = View::Sensor;
  float eye[3] = {0, 0, 0};
  float focal_px = 1.0f;  // focal length in pixels of the output picture
  float u0 = 0.0f, v0 = 0.0f;  // where the frame's centre lands, pixels
  int width = 0, height = 0;
};

// Frames `view` on the body's first-frame bounding box: the box widened to at least its height
// (a raised arm's span), plus 8 % each side, fitted into width x height pixels.
ViewCamera frameView(View view, const Bounds& body, int width, int height);

// One mesh to draw: positions, optional per-vertex normals (computed from the faces when null),
// triangle indices, and its colour (linear 0..1).
struct MeshRef {
  const drape_vec3* positions = nullptr;
  const drape_vec3* normals = nullptr;
  uint32_t vertex_count = 0;
  const uint32_t* indices = nullptr;
  uint32_t index_count = 0;
  float color[3] = {1, 1, 1};
};

extern const float kBodyColor[3];
extern const float kGarmentColor[3];
extern const float kUnderColor[3];  // a garment under the garment (--under)
extern const uint8_t kBackground[3];

class Rasterizer {
 public:
  // Draws the meshes into `out` (resized to the camera's picture), supersampled `ss` x `ss`.
  void render(const ViewCamera& camera, const std::vector<MeshRef>& meshes, Image& out, int ss = 2);

 private:
  std::vector<float> inv_z_;     // 1 / depth, 0 = empty
  std::vector<float> shade_;     // Lambert intensity
  std::vector<uint8_t> mesh_;    // mesh index + 1, 0 = background
  std::vector<drape_vec3> face_normals_;
  struct Projected { float x, y, inv_z, shade; bool ok; };
  std::vector<Projected> projected_;
};

// Area-averaging resize (for downscaling), used for the contact sheet.
void resizeImage(const Image& src, int width, int height, Image& dst);
// Copies `src` into `dst` with its top-left corner at (x, y), clipped.
void blit(const Image& src, Image& dst, int x, int y);
// Draws upper-case ASCII text with a 5x7 font scaled by `scale`, top-left at (x, y).
// Unsupported characters draw as blanks.
void drawText(Image& img, int x, int y, const std::string& text, int scale, const uint8_t color[3]);
// Width in pixels of drawText's output.
int textWidth(const std::string& text, int scale);
void fillRect(Image& img, int x, int y, int w, int h, const uint8_t color[3]);

}  // namespace replay
