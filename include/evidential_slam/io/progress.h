// A terminal progress line for long offline runs: scans done/total, rate and ETA. On a TTY it
// redraws one line with '\r' a few times a second; into a file or pipe it prints a plain line
// every ~10 % so logs stay readable.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace evidential_slam {
namespace io {

class ProgressBar {
 public:
  // `total` 0 means unknown (no percentage, no ETA).
  ProgressBar(std::FILE* stream, uint64_t total, bool is_tty);
  // Reports `done` scans; draws when due.
  void update(uint64_t done);
  // Final state; ends the TTY line.
  void finish(uint64_t done);
  // Clears the current TTY line so another message can be printed; the next update redraws.
  void clearLine();

  // The text of one progress line (without '\r' / '\n'), exposed for tests.
  static std::string format(uint64_t done, uint64_t total, double elapsed_s);

 private:
  void draw(uint64_t done, bool final_line);

  std::FILE* stream_;
  uint64_t total_;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  int next_decile_ = 1;
  bool line_open_ = false;
};

}  // namespace io
}  // namespace evidential_slam
