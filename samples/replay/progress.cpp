#include "progress.h"

#include <algorithm>
#include <cstdio>
#include <string>

#if defined(_WIN32)
#include <io.h>
#define DRAPE_ISATTY _isatty
#define DRAPE_FILENO _fileno
#else
#include <unistd.h>
#define DRAPE_ISATTY isatty
#define DRAPE_FILENO fileno
#endif

namespace replay {

namespace {
constexpr double kShowAfterS = 1.0;
constexpr double kRedrawS = 0.1;
constexpr int kBarWidth = 30;
}  // namespace

bool stderrIsTerminal() { return DRAPE_ISATTY(DRAPE_FILENO(stderr)) != 0; }

ProgressBar::ProgressBar(uint32_t total, bool enabled)
    : total_(total), enabled_(enabled && total > 0), start_(Clock::now()), last_draw_(start_) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(uint32_t done) {
  if (!enabled_) return;
  const Clock::time_point now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < kShowAfterS) return;
  if (drawn_ && std::chrono::duration<double>(now - last_draw_).count() < kRedrawS && done < total_) return;
  last_draw_ = now;
  done = std::min(done, total_);
  const double fraction = static_cast<double>(done) / total_;
  const int filled = static_cast<int>(fraction * kBarWidth);
  std::string bar(static_cast<size_t>(filled), '#');
  bar.append(static_cast<size_t>(kBarWidth - filled), '.');
  const double left = done > 0 ? elapsed * (total_ - done) / done : 0.0;
  std::fprintf(stderr, "\rdrape-replay [%s] %u/%u frames, %.1f s, %.1f s left  ", bar.c_str(), done, total_,
               elapsed, left);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!drawn_) return;
  std::fprintf(stderr, "\r%*s\r", 90, "");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace replay
