// drape-replay's pictures: per rendered frame one PNG with the chosen views side by side
// (render_NNNNN.png), a contact sheet of 12 frames across the take (contact_sheet.png), an
// animated GIF of the rendered frames (replay.gif) and, when ffmpeg is on PATH, an MP4
// (replay.mp4). Rendering happens outside the timed library calls.
#pragma once

#include "image_io.h"
#include "options.h"
#include "render.h"
#include "stats.h"

#include <drape/drape.h>

#include <string>
#include <vector>

namespace replay {

class Pictures {
 public:
  // `frames`: frames that will be replayed; `rate_hz`: the recording's nominal rate (0: 30 Hz).
  // Fills the settings part of `stats`. Does nothing (active() false) when no pictures are due.
  void begin(const Options& options, uint32_t frames, double rate_hz, const std::string& recording_name,
             const std::string& garment_name, RenderStats& stats);
  bool active() const { return every_ != 0; }
  // Whether frame `index` (of the recording) will be drawn; then its normals are needed.
  bool wanted(uint32_t index) const;

  // Called for every updated frame with its meshes (the garment's may be empty).
  bool addFrame(uint32_t index, double timestamp, const std::vector<drape_vec3>& body_positions,
                const std::vector<drape_vec3>& body_normals, const std::vector<uint32_t>& body_indices,
                const std::vector<drape_vec3>& garment_positions, const std::vector<drape_vec3>& garment_normals,
                const std::vector<uint32_t>& garment_indices, RenderStats& stats, std::string& error);

  // A garment worn under the garment (--under), drawn before it in kUnderColor from these buffers
  // (the caller's, read at each addFrame; empty: not drawn).
  void setUnderGarment(const std::vector<drape_vec3>* positions, const std::vector<drape_vec3>* normals,
                       const std::vector<uint32_t>* indices) {
    under_positions_ = positions;
    under_normals_ = normals;
    under_indices_ = indices;
  }

  // Writes the contact sheet, closes the GIF, makes the MP4.
  bool finish(RenderStats& stats, std::string& error);

 private:
  const std::vector<drape_vec3>* under_positions_ = nullptr;
  const std::vector<drape_vec3>* under_normals_ = nullptr;
  const std::vector<uint32_t>* under_indices_ = nullptr;
  void composeFrame(const std::vector<MeshRef>& meshes, bool labels, uint32_t index, double timestamp, Image& out);

  uint32_t every_ = 0;
  uint32_t frames_ = 0;
  double rate_hz_ = 30.0;
  std::string dir_;
  std::string title_;
  std::vector<View> views_;
  int width_ = 0, height_ = 0;
  bool framed_ = false;
  std::vector<ViewCamera> cameras_;
  Rasterizer raster_;
  Image view_image_, frame_image_, sheet_frame_, cell_;
  // Contact sheet: the recording indices wanted, and the cells drawn so far.
  std::vector<uint32_t> sheet_targets_;
  size_t next_sheet_ = 0;
  Image sheet_;
  int cell_w_ = 0, cell_h_ = 0, columns_ = 4, header_h_ = 0;
  GifWriter gif_;
  std::string gif_path_;
  std::vector<std::string> png_names_;
};

}  // namespace replay
