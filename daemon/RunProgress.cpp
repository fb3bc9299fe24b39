#include "daemon/RunProgress.h"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace rotafab::cli {

std::string minutes(double seconds) {
  const int s = static_cast<int>(std::lround(seconds));
  return s >= 60 ? fmt::format("{}m {:02}s", s / 60, s % 60) : fmt::format("{}s", s);
}

void ProgressBar::operator()(const devices::Progress& p) {
  const int percent = static_cast<int>(100 * p.bytesAcknowledged / std::max<size_t>(p.bytesTotal, 1));
  const auto now = std::chrono::steady_clock::now();
  if (terminal_ ? now - lastShown_ < std::chrono::milliseconds(200) && percent != 100
                : percent / 10 == lastPercent_ / 10) {
    return;
  }
  lastShown_ = now, lastPercent_ = percent;
  const int filled = percent / 5;
  fmt::print(stderr, "{}run: sheet {} [{}{}] {:3}%  stroke {} of {}, {} left{}", terminal_ ? "\r" : "", p.sheet,
             std::string(filled, '#'), std::string(20 - filled, '.'), percent, p.stroke, p.strokes,
             minutes(p.secondsLeft), terminal_ ? "" : "\n");
}

void ProgressBar::end() const {
  if (terminal_) fmt::print(stderr, "\n");
}

bool waitForEnter(const core::Cancellation& cancel) {
  for (;;) {
    if (cancel.cancelled()) return false;
    pollfd input{STDIN_FILENO, POLLIN, 0};
    if (::poll(&input, 1, 200) > 0) {
      char byte = 0;
      while (::read(STDIN_FILENO, &byte, 1) == 1) {
        if (byte == '\n') return true;
      }
      return false;
    }
  }
}

}  // namespace rotafab::cli
