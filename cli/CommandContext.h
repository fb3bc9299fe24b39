#pragma once
// The work context of one command-line verb (core/WorkContext.h): an
// executor on every core, Ctrl-C and SIGTERM cancelling the work, notes and
// warnings printed as "note: ..." and "warning: ..." lines, progress
// rendered as the verb renders it. The two signals are blocked in every
// thread of the program from the moment this is made, and one thread of its
// own waits for them, so no handler and no global flag is involved, and a
// signal reaches the command even when the shell started it in the
// background (where SIGINT would be ignored). A second signal ends a
// command that allows it at once (`make`, `nest`: nothing is cut there);
// `run` never, as it must wait for the machine to stop.

#include <atomic>
#include <csignal>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "core/WorkContext.h"

namespace rotafab::cli {

class CommandContext {
 public:
  // `threads`: the executor's size; 0: one per core.
  enum class SecondSignal { Ends, Waits };
  explicit CommandContext(core::ProgressSink progress = {}, unsigned threads = 0,
                          SecondSignal second = SecondSignal::Ends);
  ~CommandContext();
  CommandContext(const CommandContext&) = delete;
  CommandContext& operator=(const CommandContext&) = delete;

  [[nodiscard]] const core::WorkContext& context() const { return *context_; }
  [[nodiscard]] core::Cancellation& cancellation() { return cancellation_; }
  // The signal that cancelled the work (SIGINT, SIGTERM), or 0.
  [[nodiscard]] int signal() const { return signal_; }
  // The exit status of a command its signal stopped: 128 + the signal, as a shell reports it.
  [[nodiscard]] int interruptedStatus() const { return 128 + signal_; }
  // The notes and warnings printed so far, in order, without "note: " or "warning: ".
  [[nodiscard]] std::vector<std::string> notes() const;
  [[nodiscard]] std::vector<std::string> warnings() const;

 private:
  class MessageLines;
  std::shared_ptr<MessageLines> lines_;
  sigset_t blocked_{}, previous_{};
  SecondSignal second_;
  core::Cancellation cancellation_;
  std::atomic<int> signal_{0};
  std::atomic<bool> stopping_{false};
  std::thread watcher_;
  std::unique_ptr<core::Executor> executor_;
  std::unique_ptr<core::WorkContext> context_;
};

}  // namespace rotafab::cli
