#include "cli/CommandContext.h"

#include <fmt/format.h>
#include <pthread.h>
#include <spdlog/logger.h>
#include <spdlog/sinks/base_sink.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <string>
#include <vector>

namespace rotafab::cli {
namespace {}  // namespace

// Notes and warnings on standard error, one line each, as the command line
// has always printed them, and kept for a summary that lists them.
class CommandContext::MessageLines : public spdlog::sinks::base_sink<std::mutex> {
 public:
  [[nodiscard]] std::vector<std::string> kept(bool warnings) {
    const std::lock_guard lock(this->mutex_);
    return warnings ? warnings_ : notes_;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    const bool warning = message.level >= spdlog::level::warn;
    std::string line(message.payload.data(), message.payload.size());
    fmt::print(stderr, "{}: {}\n", warning ? "warning" : "note", line);
    (warning ? warnings_ : notes_).push_back(std::move(line));
  }
  void flush_() override { std::fflush(stderr); }

 private:
  std::vector<std::string> notes_, warnings_;
};

std::vector<std::string> CommandContext::notes() const { return lines_->kept(false); }
std::vector<std::string> CommandContext::warnings() const { return lines_->kept(true); }

CommandContext::CommandContext(core::ProgressSink progress, unsigned threads, SecondSignal second) : second_(second) {
  sigemptyset(&blocked_);
  sigaddset(&blocked_, SIGINT);
  sigaddset(&blocked_, SIGTERM);
  // Before any thread starts: they all inherit the mask.
  pthread_sigmask(SIG_BLOCK, &blocked_, &previous_);
  watcher_ = std::thread([this] {
    const timespec tick{0, 50'000'000};  // how soon a stopping context is noticed
    while (!stopping_) {
      const int got = sigtimedwait(&blocked_, nullptr, &tick);
      if (got != SIGINT && got != SIGTERM) continue;
      if (signal_ != 0 && second_ == SecondSignal::Ends) {
        // Asked twice: go now, as the signal would have ended it.
        std::signal(got, SIG_DFL);
        pthread_sigmask(SIG_UNBLOCK, &blocked_, nullptr);
        std::raise(got);
      }
      if (signal_ == 0) signal_ = got;
      cancellation_.cancel();
    }
  });
  executor_ =
      std::make_unique<core::Executor>(threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency()));
  lines_ = std::make_shared<MessageLines>();
  auto log = std::make_shared<spdlog::logger>("rotafab", lines_);
  log->set_level(spdlog::level::info);
  context_ = std::make_unique<core::WorkContext>(*executor_, cancellation_, std::move(progress), std::move(log));
}

CommandContext::~CommandContext() {
  context_.reset();
  executor_.reset();
  stopping_ = true;
  watcher_.join();
  // A signal that came once the watcher was done is the command's, not a
  // reason to end the program now that it is done.
  const timespec none{0, 0};
  while (sigtimedwait(&blocked_, nullptr, &none) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
}

}  // namespace rotafab::cli
