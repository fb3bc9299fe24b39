#include "cli/RunProgress.h"

#include <fmt/format.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <memory>

namespace rotafab::cli {

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

bool waitForEnter(const core::Cancellation& cancel) { return readLine(cancel).has_value(); }

std::optional<std::string> readLine(const core::Cancellation& cancel) {
  std::string line;
  for (;;) {
    if (cancel.cancelled()) return std::nullopt;
    pollfd input{STDIN_FILENO, POLLIN, 0};
    if (::poll(&input, 1, 200) > 0) {
      char byte = 0;
      while (::read(STDIN_FILENO, &byte, 1) == 1) {
        if (byte == '\n') return line;
        line += byte;
      }
      return std::nullopt;
    }
  }
}

devices::RunEvents terminalRunEvents(size_t sheets, const core::Cancellation& cancel, std::string stock,
                                     std::map<int, std::string> kits, TerminalFraming framing, core::LengthUnit unit) {
  const bool terminal = ::isatty(STDERR_FILENO) != 0;
  auto bar = std::make_shared<ProgressBar>(terminal);
  // "; its kit: steps 174-352; once cut, ..." for a sheet the manifest gives a kit.
  auto kitOf = [kits = std::make_shared<const std::map<int, std::string>>(std::move(kits))](int sheet) {
    const auto kit = kits->find(sheet);
    return kit == kits->end() ? std::string() : fmt::format(" (its kit: {})", kit->second);
  };
  devices::RunEvents events;
  events.beforeSheet = [&cancel, kitOf, stock, framing](size_t index, const jobs::Toolpath& sheet, bool framed) {
    using devices::SheetGo;
    if (!framed) {
      if (index > 0) {
        fmt::print(stderr, "run: load sheet {}, {}{}, and press Enter (Ctrl-C stops)\n", sheet.sheet, stock,
                   kitOf(sheet.sheet));
        if (!waitForEnter(cancel)) return SheetGo::Stop;  // Ctrl-C or the end of input: stop, do not cut blind
      }
      return framing.frame ? SheetGo::Frame : SheetGo::Cut;
    }
    if (framing.yes) return SheetGo::Cut;
    for (;;) {
      fmt::print(stderr, "run: sheet {} framed: cut sheet {} now? [y/N, f to frame it again] ", sheet.sheet,
                 sheet.sheet);
      std::fflush(stderr);
      const std::optional<std::string> answer = readLine(cancel);
      if (!answer) return SheetGo::Stop;
      if (*answer == "y" || *answer == "Y" || *answer == "yes") return SheetGo::Cut;
      if (*answer == "f" || *answer == "F") return SheetGo::Frame;
      return SheetGo::Stop;
    }
  };
  events.sheetStarted = [bar, sheets, terminal, kitOf, stock, unit](size_t s, const jobs::Toolpath& toolpath,
                                                                    size_t fromStroke, double seconds) {
    // A simulator faster than real: its time, and the machine's it stands for (of a whole sheet).
    const std::string machineTime = fromStroke == 0 && std::abs(seconds - toolpath.seconds) > 0.5
                                        ? fmt::format(" ({} on the machine simulated)", minutes(toolpath.seconds))
                                        : "";
    const std::string strokes =
        fromStroke == 0 ? fmt::format("{} strokes, {} to burn", toolpath.strokes.size(), unit(toolpath.burnLength, 1))
                        : fmt::format("strokes {} to {} (the {} before were cut)", fromStroke + 1,
                                      toolpath.strokes.size(), fromStroke);
    fmt::print(stderr, "run: sheet {} ({} of {}), {}: {}, about {}{}{}\n", toolpath.sheet, s + 1, sheets, stock,
               strokes, minutes(seconds), machineTime, kitOf(toolpath.sheet));
    *bar = ProgressBar(terminal);
  };
  events.framing = [](const jobs::Toolpath& sheet) {
    fmt::print(stderr, "run: framing ({})\n", profiles::frameLight(sheet.framePower));
  };
  events.progress = [bar](const devices::Progress& p) { (*bar)(p); };
  events.sheetFinished = [bar] { bar->end(); };
  events.stopped = [bar] { bar->end(); };
  return events;
}

}  // namespace rotafab::cli
