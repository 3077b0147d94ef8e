// Progress line. See progress.h.
#include "evidential_slam/io/progress.h"

#include <cmath>

namespace evidential_slam {
namespace io {
namespace {

std::string duration(double s) {
  if (!std::isfinite(s) || s < 0) return "--:--";
  const long total = std::lround(s);
  char buf[32];
  if (total >= 3600) {
    std::snprintf(buf, sizeof(buf), "%ld:%02ld:%02ld", total / 3600, (total / 60) % 60, total % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%ld:%02ld", total / 60, total % 60);
  }
  return buf;
}

}  // namespace

ProgressBar::ProgressBar(std::FILE* stream, uint64_t total, bool is_tty)
    : stream_(stream),
      total_(total),
      tty_(is_tty),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

std::string ProgressBar::format(uint64_t done, uint64_t total, double elapsed_s) {
  const double rate = elapsed_s > 0 ? static_cast<double>(done) / elapsed_s : 0.0;
  char buf[160];
  if (total > 0) {
    const double frac = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
    constexpr int kWidth = 24;
    const int filled = static_cast<int>(frac * kWidth);
    std::string bar(static_cast<size_t>(filled), '#');
    bar.append(static_cast<size_t>(kWidth - filled), '.');
    const double eta = rate > 0 ? static_cast<double>(total - std::min(done, total)) / rate : NAN;
    std::snprintf(buf, sizeof(buf), "[%s] %llu/%llu scans %5.1f%%  %.1f scans/s  ETA %s",
                  bar.c_str(), static_cast<unsigned long long>(done),
                  static_cast<unsigned long long>(total), 100.0 * frac, rate,
                  duration(eta).c_str());
  } else {
    std::snprintf(buf, sizeof(buf), "%llu scans  %.1f scans/s  elapsed %s",
                  static_cast<unsigned long long>(done), rate, duration(elapsed_s).c_str());
  }
  return buf;
}

void ProgressBar::update(uint64_t done) {
  if (stream_ == nullptr) return;
  const auto now = std::chrono::steady_clock::now();
  if (tty_) {
    if (now - last_draw_ < std::chrono::milliseconds(200) && line_open_) return;
    last_draw_ = now;
    draw(done, false);
    return;
  }
  if (total_ == 0) return;
  const int decile = static_cast<int>(10 * done / total_);
  if (decile < next_decile_ || done >= total_) return;  // 100 % is printed by finish()
  next_decile_ = decile + 1;
  draw(done, false);
}

void ProgressBar::finish(uint64_t done) {
  if (stream_ == nullptr) return;
  draw(done, true);
}

void ProgressBar::clearLine() {
  if (stream_ == nullptr || !tty_ || !line_open_) return;
  std::fputs("\r\033[K", stream_);
  line_open_ = false;
}

void ProgressBar::draw(uint64_t done, bool final_line) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const std::string text = format(done, total_, elapsed);
  if (tty_) {
    std::fprintf(stream_, "\r\033[K%s%s", text.c_str(), final_line ? "\n" : "");
    line_open_ = !final_line;
  } else {
    std::fprintf(stream_, "%s\n", text.c_str());
  }
  std::fflush(stream_);
}

}  // namespace io
}  // namespace evidential_slam
