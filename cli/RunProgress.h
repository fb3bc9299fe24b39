#pragma once
// How `rotafab run` shows a cut at the terminal: the progress bar, times in
// minutes, and the question before each sheet after the first.

#include <chrono>
#include <map>
#include <string>

#include "core/Cancellation.h"
#include "core/Duration.h"
#include "core/LengthUnit.h"
#include "devices/Device.h"
#include "devices/JobRun.h"

namespace rotafab::cli {

using core::minutes;

// A bar redrawn in place on a terminal (at most every 200 ms), a line every
// 10% otherwise.
class ProgressBar {
 public:
  explicit ProgressBar(bool terminal) : terminal_(terminal) {}
  void operator()(const devices::Progress& progress);
  // After a sheet, or a fault: the bar's line ended.
  void end() const;

 private:
  bool terminal_;
  std::chrono::steady_clock::time_point lastShown_{};
  int lastPercent_ = -1;
};

// Waits for a line on standard input while watching for a cancel (a read
// restarted after a signal would not see it). False on a cancel or the end of input.
bool waitForEnter(const core::Cancellation& cancel);
// A line typed at the terminal, without its newline; nothing on a cancel
// (Ctrl-C) or at the end of input.
std::optional<std::string> readLine(const core::Cancellation& cancel);

// Framing before each sheet (`rotafab run --frame`), and whether to cut
// once framed without asking (--yes).
struct TerminalFraming {
  bool frame = false, yes = false;
};

// The events of a run of `sheets` sheets shown on standard error: a line as
// each sheet starts, its progress bar, the question before each sheet after
// the first (answered at the terminal), the framing and the question after
// it ("cut sheet 2 now? [y/N]"). `stock`: what each
// sheet is (jobs::stockOf(), "posterboard (0.031 in), 32 x 18 in"); `kits`:
// each sheet's kit by its number, as the job's manifest says it
// (ManifestSheets::kits); `unit`: of the lengths said.
devices::RunEvents terminalRunEvents(size_t sheets, const core::Cancellation& cancel, std::string stock,
                                     std::map<int, std::string> kits = {}, TerminalFraming framing = {},
                                     core::LengthUnit unit = {});

}  // namespace rotafab::cli
