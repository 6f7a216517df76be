#include "pictures.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace fs = std::filesystem;

namespace replay {

namespace {

constexpr int kSheetCells = 12;        // 4 x 3
constexpr int kSheetMaxWidth = 1280;   // pixels; cells shrink to fit
constexpr int kCellGap = 4;
const uint8_t kInk[3] = {40, 44, 52};
const uint8_t kSeparator[3] = {190, 196, 204};

std::string frameLabel(uint32_t index, double timestamp) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "FRAME %u  T %.2f S", index, timestamp);
  return buf;
}

}  // namespace

void Pictures::begin(const Options& opt, uint32_t frames, double rate_hz, const std::string& recording_name,
                     const std::string& garment_name, RenderStats& st) {
  st.png_available = pngAvailable();
  st.camera = opt.camera;
  st.width = opt.width;
  st.height = opt.height;
  st.every = resolveRenderEvery(opt, frames);
  st.dir = opt.out_dir;
  every_ = st.png_available ? st.every : 0;
  if (every_ == 0) return;
  frames_ = frames;
  rate_hz_ = std::isfinite(rate_hz) && rate_hz > 0.0 ? rate_hz : 30.0;
  dir_ = opt.out_dir;
  width_ = static_cast<int>(opt.width);
  height_ = static_cast<int>(opt.height);
  views_.clear();
  if (opt.camera != "side") views_.push_back(View::Sensor);
  if (opt.camera != "sensor") views_.push_back(View::Side);
  title_ = "DRAPE-REPLAY  " + recording_name + "  " + garment_name;

  // Contact sheet: kSheetCells frames evenly spread over the take (all of them if fewer).
  const uint32_t cells = std::min<uint32_t>(kSheetCells, frames);
  sheet_targets_.clear();
  for (uint32_t k = 0; k < cells; ++k)
    sheet_targets_.push_back(cells == 1 ? 0 : static_cast<uint32_t>(std::lround(
                                                   static_cast<double>(k) * (frames - 1) / (cells - 1))));
  next_sheet_ = 0;
  const int frame_w = width_ * static_cast<int>(views_.size());
  const double scale = std::min(1.0, static_cast<double>(kSheetMaxWidth - (columns_ + 1) * kCellGap) /
                                         (columns_ * frame_w));
  cell_w_ = std::max(1, static_cast<int>(std::lround(frame_w * scale)));
  cell_h_ = std::max(1, static_cast<int>(std::lround(height_ * scale)));
  const int rows = (static_cast<int>(cells) + columns_ - 1) / columns_;
  header_h_ = 7 * 2 + 2 * 6;
  sheet_.resize(columns_ * cell_w_ + (columns_ + 1) * kCellGap, header_h_ + rows * (cell_h_ + kCellGap), kSeparator);
  fillRect(sheet_, 0, 0, sheet_.width, header_h_, kBackground);
  drawText(sheet_, kCellGap + 2, 6, title_, 2, kInk);

  std::string error;
  if (gifAvailable()) {
    gif_path_ = (fs::path(dir_) / "replay.gif").string();
    const int delay_cs = static_cast<int>(std::lround(100.0 * every_ / rate_hz_));
    if (!gif_.open(gif_path_, frame_w, height_, delay_cs, error)) gif_path_.clear();
  }
  png_names_.clear();
  framed_ = false;
}

bool Pictures::wanted(uint32_t index) const {
  if (every_ == 0) return false;
  if (index % every_ == 0) return true;
  return next_sheet_ < sheet_targets_.size() && sheet_targets_[next_sheet_] <= index;
}

void Pictures::composeFrame(const std::vector<MeshRef>& meshes, bool labels, uint32_t index, double timestamp,
                            Image& out) {
  out.resize(width_ * static_cast<int>(views_.size()), height_, kBackground);
  const int text_scale = width_ >= 320 ? 2 : 1;
  for (size_t v = 0; v < views_.size(); ++v) {
    raster_.render(cameras_[v], meshes, view_image_, 2);
    if (labels) drawText(view_image_, 4 * text_scale, 4 * text_scale, viewLabel(views_[v]), text_scale, kInk);
    blit(view_image_, out, static_cast<int>(v) * width_, 0);
    if (v > 0) fillRect(out, static_cast<int>(v) * width_ - 1, 0, 2, height_, kSeparator);
  }
  if (labels)
    drawText(out, 4 * text_scale, height_ - 11 * text_scale, frameLabel(index, timestamp), text_scale, kInk);
}

bool Pictures::addFrame(uint32_t index, double timestamp, const std::vector<drape_vec3>& body_positions,
                        const std::vector<drape_vec3>& body_normals, const std::vector<uint32_t>& body_indices,
                        const std::vector<drape_vec3>& garment_positions,
                        const std::vector<drape_vec3>& garment_normals, const std::vector<uint32_t>& garment_indices,
                        RenderStats& st, std::string& error) {
  if (every_ == 0) return true;
  if (!framed_) {  // framed on the first updated frame's body
    const Bounds b = boundsOf(body_positions);
    cameras_.clear();
    for (View v : views_) cameras_.push_back(frameView(v, b, width_, height_));
    framed_ = true;
  }
  const bool scheduled = index % every_ == 0;
  const bool for_sheet = next_sheet_ < sheet_targets_.size() && sheet_targets_[next_sheet_] <= index;
  if (!scheduled && !for_sheet) return true;

  std::vector<MeshRef> meshes(1);
  meshes[0].positions = body_positions.data();
  meshes[0].normals = body_normals.size() == body_positions.size() ? body_normals.data() : nullptr;
  meshes[0].vertex_count = static_cast<uint32_t>(body_positions.size());
  meshes[0].indices = body_indices.data();
  meshes[0].index_count = static_cast<uint32_t>(body_indices.size());
  std::copy(kBodyColor, kBodyColor + 3, meshes[0].color);
  if (under_positions_ && under_indices_ && !under_positions_->empty() && !under_indices_->empty()) {
    MeshRef u;
    u.positions = under_positions_->data();
    u.normals = under_normals_ && under_normals_->size() == under_positions_->size() ? under_normals_->data() : nullptr;
    u.vertex_count = static_cast<uint32_t>(under_positions_->size());
    u.indices = under_indices_->data();
    u.index_count = static_cast<uint32_t>(under_indices_->size());
    std::copy(kUnderColor, kUnderColor + 3, u.color);
    meshes.push_back(u);
  }
  if (!garment_positions.empty() && !garment_indices.empty()) {
    MeshRef g;
    g.positions = garment_positions.data();
    g.normals = garment_normals.size() == garment_positions.size() ? garment_normals.data() : nullptr;
    g.vertex_count = static_cast<uint32_t>(garment_positions.size());
    g.indices = garment_indices.data();
    g.index_count = static_cast<uint32_t>(garment_indices.size());
    std::copy(kGarmentColor, kGarmentColor + 3, g.color);
    meshes.push_back(g);
  }

  using Clock = std::chrono::steady_clock;
  const Clock::time_point t0 = Clock::now();
  if (scheduled) composeFrame(meshes, true, index, timestamp, frame_image_);
  if (for_sheet) composeFrame(meshes, false, index, timestamp, sheet_frame_);
  st.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());

  if (scheduled) {
    char name[32];
    std::snprintf(name, sizeof name, "render_%05u.png", index);
    if (!writePng((fs::path(dir_) / name).string(), frame_image_, error)) return false;
    png_names_.push_back(name);
    ++st.frames_rendered;
    if (gif_.isOpen() && !gif_.addFrame(frame_image_, error)) return false;
  }
  if (for_sheet) {
    const int cell = static_cast<int>(next_sheet_);
    // A rejected stretch of frames may have skipped targets: this frame fills the next cell only.
    while (next_sheet_ < sheet_targets_.size() && sheet_targets_[next_sheet_] <= index) ++next_sheet_;
    resizeImage(sheet_frame_, cell_w_, cell_h_, cell_);
    const std::string label = frameLabel(index, timestamp);
    fillRect(cell_, 0, cell_h_ - 11, textWidth(label, 1) + 6, 11, kBackground);
    drawText(cell_, 3, cell_h_ - 9, label, 1, kInk);
    const int col = cell % columns_, row = cell / columns_;
    blit(cell_, sheet_, kCellGap + col * (cell_w_ + kCellGap), header_h_ + row * (cell_h_ + kCellGap));
  }
  return true;
}

bool Pictures::finish(RenderStats& st, std::string& error) {
  if (every_ == 0) return true;
  if (next_sheet_ > 0) {
    const std::string path = (fs::path(dir_) / "contact_sheet.png").string();
    if (!writePng(path, sheet_, error)) return false;
    st.contact_sheet = path;
  }
  if (gif_.isOpen()) {
    if (!gif_.close(error)) return false;
    if (st.frames_rendered > 0) st.gif = gif_path_;
  }
  const std::string ffmpeg = findOnPath("ffmpeg");
  if (ffmpeg.empty()) {
    st.mp4_note = "ffmpeg not on PATH";
  } else if (png_names_.size() < 2) {
    st.mp4_note = "fewer than 2 frames";
  } else {
    const std::string path = (fs::path(dir_) / "replay.mp4").string();
    std::string mp4_error;
    if (writeMp4(ffmpeg, dir_, png_names_, rate_hz_ / every_, path, mp4_error)) st.mp4 = path;
    else st.mp4_note = mp4_error;
  }
  return true;
}

}  // namespace replay
