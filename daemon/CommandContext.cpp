#include "daemon/CommandContext.h"

#include <fmt/format.h>
#include <pthread.h>
#include <spdlog/logger.h>
#include <spdlog/sinks/base_sink.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <mutex>

namespace rotafab::cli {
namespace {

// Notes and warnings on standard error, one line each, as the command line has always printed them.
class MessageLines : public spdlog::sinks::base_sink<std::mutex> {
 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    const char* kind = message.level >= spdlog::level::warn ? "warning" : "note";
    fmt::print(stderr, "{}: {}\n", kind, std::string_view(message.payload.data(), message.payload.size()));
  }
  void flush_() override { std::fflush(stderr); }
};

}  // namespace

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
  auto log = std::make_shared<spdlog::logger>("rotafab", std::make_shared<MessageLines>());
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
