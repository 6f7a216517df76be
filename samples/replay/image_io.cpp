#include "image_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

#if defined(DRAPE_REPLAY_HAVE_STB)
// stb_image_write (public domain, Debian's libstb-dev): the implementation is compiled into this
// file, private to it.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>
#endif

#if defined(DRAPE_REPLAY_HAVE_GIF)
#include <gif_lib.h>
#endif

#if !defined(_WIN32)
#include <fcntl.h>
#include <unistd.h>
#endif

namespace fs = std::filesystem;

namespace replay {

bool pngAvailable() {
#if defined(DRAPE_REPLAY_HAVE_STB)
  return true;
#else
  return false;
#endif
}

bool gifAvailable() {
#if defined(DRAPE_REPLAY_HAVE_GIF)
  return true;
#else
  return false;
#endif
}

bool writePng(const std::string& path, const Image& image, std::string& error) {
#if defined(DRAPE_REPLAY_HAVE_STB)
  stbi_write_png_compression_level = 9;
  if (image.width <= 0 || image.height <= 0 ||
      !stbi_write_png(path.c_str(), image.width, image.height, 3, image.rgb.data(), image.width * 3)) {
    error = "cannot write PNG '" + path + "'; check that the --out folder is writable and has space";
    return false;
  }
  return true;
#else
  (void)image;
  error = "cannot write PNG '" + path + "': drape-replay was built without stb_image_write (install libstb-dev)";
  return false;
#endif
}

// ---------------------------------------------------------------------------------------------
// GIF
// ---------------------------------------------------------------------------------------------
struct GifWriter::Impl {
#if defined(DRAPE_REPLAY_HAVE_GIF)
  GifFileType* gif = nullptr;
  int width = 0, height = 0, delay_cs = 0;
  std::vector<GifColorType> palette;
  std::vector<int16_t> lut;  // 5 bits per channel -> palette index, -1 = not computed yet
  std::vector<GifByteType> row;

  void buildPalette() {
    palette.clear();
    auto add = [&](float r, float g, float b) {
      if (palette.size() >= 256) return;
      auto c8 = [](float v) { return static_cast<GifByteType>(std::lround(std::min(std::max(v, 0.0f), 1.0f) * 255.0f)); };
      palette.push_back(GifColorType{c8(r), c8(g), c8(b)});
    };
    const float bg[3] = {kBackground[0] / 255.0f, kBackground[1] / 255.0f, kBackground[2] / 255.0f};
    add(bg[0], bg[1], bg[2]);
    for (int i = 0; i < 16; ++i) {  // greys: text, outlines
      const float g = static_cast<float>(i) / 15.0f;
      add(g, g, g);
    }
    for (const float* col : {kBodyColor, kGarmentColor})
      for (int i = 0; i < 64; ++i) {  // shading ramps
        const float s = 0.05f + 0.95f * static_cast<float>(i) / 63.0f;
        add(col[0] * s, col[1] * s, col[2] * s);
      }
    // Anti-aliased edges: blends of the background with lit and outlined surfaces, and of the
    // body with the garment.
    for (const float* col : {kBodyColor, kGarmentColor})
      for (float s : {0.35f, 0.7f, 1.0f})
        for (int i = 1; i < 8; ++i) {
          const float t = static_cast<float>(i) / 8.0f;
          add(bg[0] * (1 - t) + col[0] * s * t, bg[1] * (1 - t) + col[1] * s * t, bg[2] * (1 - t) + col[2] * s * t);
        }
    for (int i = 1; i < 8; ++i) {
      const float t = static_cast<float>(i) / 8.0f;
      add(bg[0] * (1 - t) * 0.35f + bg[0] * t, bg[1] * (1 - t) * 0.35f + bg[1] * t, bg[2] * (1 - t) * 0.35f + bg[2] * t);
    }
    for (int i = 1; i < 8; ++i)
      for (float s : {0.5f, 0.8f}) {
        const float t = static_cast<float>(i) / 8.0f;
        add((kBodyColor[0] * (1 - t) + kGarmentColor[0] * t) * s, (kBodyColor[1] * (1 - t) + kGarmentColor[1] * t) * s,
            (kBodyColor[2] * (1 - t) + kGarmentColor[2] * t) * s);
      }
    while (palette.size() < 256) palette.push_back(GifColorType{0, 0, 0});
    lut.assign(32 * 32 * 32, -1);
  }

  GifByteType index(const uint8_t* p) {
    const int key = ((p[0] >> 3) << 10) | ((p[1] >> 3) << 5) | (p[2] >> 3);
    if (lut[static_cast<size_t>(key)] < 0) {
      const int r = (p[0] & 0xf8) | 4, g = (p[1] & 0xf8) | 4, b = (p[2] & 0xf8) | 4;
      int best = 0;
      long best_d = -1;
      for (size_t i = 0; i < palette.size(); ++i) {
        const long dr = r - palette[i].Red, dg = g - palette[i].Green, db = b - palette[i].Blue;
        const long d = 3 * dr * dr + 4 * dg * dg + 2 * db * db;
        if (best_d < 0 || d < best_d) {
          best_d = d;
          best = static_cast<int>(i);
        }
      }
      lut[static_cast<size_t>(key)] = static_cast<int16_t>(best);
    }
    return static_cast<GifByteType>(lut[static_cast<size_t>(key)]);
  }
#endif
};

GifWriter::GifWriter() : impl_(new Impl) {}
GifWriter::~GifWriter() {
  std::string ignored;
  close(ignored);
}

bool GifWriter::isOpen() const {
#if defined(DRAPE_REPLAY_HAVE_GIF)
  return impl_->gif != nullptr;
#else
  return false;
#endif
}

bool GifWriter::open(const std::string& path, int width, int height, int delay_cs, std::string& error) {
#if defined(DRAPE_REPLAY_HAVE_GIF)
  close(error);
  int err = 0;
  Impl& m = *impl_;
#if defined(_WIN32)
  m.gif = EGifOpenFileName(path.c_str(), false, &err);
#else
  // EGifOpenFileName creates the file readable by its owner only; open it like any other output.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);
  if (fd < 0) err = E_GIF_ERR_OPEN_FAILED;
  m.gif = fd < 0 ? nullptr : EGifOpenFileHandle(fd, &err);
  if (!m.gif && fd >= 0) ::close(fd);
#endif
  if (!m.gif) {
    error = "cannot create GIF '" + path + "' (" + GifErrorString(err) + "); check that the --out folder is writable";
    return false;
  }
  m.width = width;
  m.height = height;
  m.delay_cs = std::max(1, std::min(delay_cs, 65535));
  m.buildPalette();
  m.row.resize(static_cast<size_t>(width));
  EGifSetGifVersion(m.gif, true);  // GIF89a: frame delays and looping
  ColorMapObject* map = GifMakeMapObject(256, m.palette.data());
  const int ok = map ? EGifPutScreenDesc(m.gif, width, height, 8, 0, map) : GIF_ERROR;
  GifFreeMapObject(map);
  static const char kNetscape[] = "NETSCAPE2.0";
  const unsigned char loop_forever[3] = {1, 0, 0};
  if (ok == GIF_ERROR || EGifPutExtensionLeader(m.gif, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
      EGifPutExtensionBlock(m.gif, 11, kNetscape) == GIF_ERROR ||
      EGifPutExtensionBlock(m.gif, 3, loop_forever) == GIF_ERROR || EGifPutExtensionTrailer(m.gif) == GIF_ERROR) {
    error = "cannot write GIF '" + path + "' (" + GifErrorString(m.gif->Error) + ")";
    EGifCloseFile(m.gif, &err);
    m.gif = nullptr;
    return false;
  }
  return true;
#else
  (void)width, (void)height, (void)delay_cs;
  error = "cannot write GIF '" + path + "': drape-replay was built without giflib (install libgif-dev)";
  return false;
#endif
}

bool GifWriter::addFrame(const Image& frame, std::string& error) {
#if defined(DRAPE_REPLAY_HAVE_GIF)
  Impl& m = *impl_;
  if (!m.gif || frame.width != m.width || frame.height != m.height) {
    error = "internal: GIF frame size mismatch";
    return false;
  }
  GraphicsControlBlock gcb{};
  gcb.DisposalMode = DISPOSE_DO_NOT;
  gcb.UserInputFlag = false;
  gcb.DelayTime = m.delay_cs;
  gcb.TransparentColor = NO_TRANSPARENT_COLOR;
  GifByteType ext[4];
  const size_t ext_len = EGifGCBToExtension(&gcb, ext);
  if (EGifPutExtension(m.gif, GRAPHICS_EXT_FUNC_CODE, static_cast<int>(ext_len), ext) == GIF_ERROR ||
      EGifPutImageDesc(m.gif, 0, 0, m.width, m.height, false, nullptr) == GIF_ERROR) {
    error = std::string("cannot write a GIF frame (") + GifErrorString(m.gif->Error) + ")";
    return false;
  }
  for (int y = 0; y < m.height; ++y) {
    for (int x = 0; x < m.width; ++x) m.row[static_cast<size_t>(x)] = m.index(frame.at(x, y));
    if (EGifPutLine(m.gif, m.row.data(), m.width) == GIF_ERROR) {
      error = std::string("cannot write a GIF frame (") + GifErrorString(m.gif->Error) + ")";
      return false;
    }
  }
  return true;
#else
  (void)frame;
  error = "drape-replay was built without giflib";
  return false;
#endif
}

bool GifWriter::close(std::string& error) {
#if defined(DRAPE_REPLAY_HAVE_GIF)
  Impl& m = *impl_;
  if (!m.gif) return true;
  int err = 0;
  const int rc = EGifCloseFile(m.gif, &err);
  m.gif = nullptr;
  if (rc == GIF_ERROR) {
    error = std::string("cannot finish the GIF (") + GifErrorString(err) + ")";
    return false;
  }
#else
  (void)error;
#endif
  return true;
}

// ---------------------------------------------------------------------------------------------
// ffmpeg
// ---------------------------------------------------------------------------------------------
std::string findOnPath(const std::string& program) {
#if defined(_WIN32)
  (void)program;
  return std::string();
#else
  const char* path = std::getenv("PATH");
  if (!path) return std::string();
  const std::string p = path;
  size_t start = 0;
  while (start <= p.size()) {
    const size_t colon = p.find(':', start);
    std::string dir = p.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    start = colon == std::string::npos ? p.size() + 1 : colon + 1;
    if (dir.empty()) dir = ".";
    const fs::path candidate = fs::path(dir) / program;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return std::string();
#endif
}

namespace {
std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += "'\\''";
    else q += c;
  }
  return q + "'";
}
}  // namespace

bool writeMp4(const std::string& ffmpeg, const std::string& dir, const std::vector<std::string>& png_names,
              double fps, const std::string& mp4_path, std::string& error) {
#if defined(_WIN32)
  (void)ffmpeg, (void)dir, (void)png_names, (void)fps, (void)mp4_path;
  error = "MP4 output is not supported on Windows";
  return false;
#else
  if (png_names.empty() || !(fps > 0.0)) {
    error = "no frames for the MP4";
    return false;
  }
  // The concat demuxer reads exactly this run's frames (a glob would pick up stale files).
  const fs::path list = fs::path(dir) / "render_frames.ffconcat";
  std::FILE* f = std::fopen(list.string().c_str(), "wb");
  if (!f) {
    error = "cannot write '" + list.string() + "'";
    return false;
  }
  std::fprintf(f, "ffconcat version 1.0\n");
  for (const std::string& name : png_names) std::fprintf(f, "file %s\nduration %.6f\n", shellQuote(name).c_str(), 1.0 / fps);
  std::fprintf(f, "file %s\n", shellQuote(png_names.back()).c_str());  // the last duration needs a next entry
  std::fclose(f);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.6f", fps);
  const std::string cmd = shellQuote(ffmpeg) + " -nostdin -hide_banner -loglevel error -y -f concat -safe 0 -i " +
                          shellQuote(list.string()) + " -vf " +
                          shellQuote(std::string("fps=") + rate + ",scale=trunc(iw/2)*2:trunc(ih/2)*2,format=yuv420p") +
                          " -c:v libx264 -movflags +faststart " + shellQuote(mp4_path) + " </dev/null";
  const int rc = std::system(cmd.c_str());
  std::error_code ec;
  fs::remove(list, ec);
  if (rc != 0) {
    error = "ffmpeg failed (exit status " + std::to_string(rc) + ") making '" + mp4_path + "'";
    return false;
  }
  return true;
#endif
}

}  // namespace replay
