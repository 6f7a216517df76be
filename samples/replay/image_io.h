// Picture files for drape-replay: PNG through stb_image_write (Debian's libstb-dev), animated GIF
// through giflib (libgif-dev), MP4 through the ffmpeg program when it is on PATH. Each is optional
// at build time (CMake finds the headers); the *Available() functions say what this build has.
#pragma once

#include "render.h"

#include <memory>
#include <string>
#include <vector>

namespace replay {

bool pngAvailable();  // built with stb_image_write
bool gifAvailable();  // built with giflib

// Writes an RGB PNG. Returns false and sets `error` on failure (or when PNG support is missing).
bool writePng(const std::string& path, const Image& image, std::string& error);

// An animated GIF89a (looping forever) written frame by frame. Each frame is mapped to one fixed
// 256-colour palette made for the rasteriser's colours (background, body, garment, outlines, text),
// so colours do not flicker between frames.
class GifWriter {
 public:
  GifWriter();
  ~GifWriter();
  GifWriter(const GifWriter&) = delete;
  GifWriter& operator=(const GifWriter&) = delete;

  // Opens `path` for frames of width x height; `delay_cs` is each frame's duration in 1/100 s.
  bool open(const std::string& path, int width, int height, int delay_cs, std::string& error);
  bool addFrame(const Image& frame, std::string& error);
  bool close(std::string& error);  // finishes the file; also done (ignoring errors) by the destructor
  bool isOpen() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The full path of `program` if an executable of that name is on PATH, else "".
std::string findOnPath(const std::string& program);

// Runs `ffmpeg` on the PNG files listed (in order) to make an H.264 MP4 at `fps`. Returns false and
// sets `error` when ffmpeg fails.
bool writeMp4(const std::string& ffmpeg, const std::string& dir, const std::vector<std::string>& png_names,
              double fps, const std::string& mp4_path, std::string& error);

}  // namespace replay
