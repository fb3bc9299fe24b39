#pragma once
// Work contexts for tests: an executor on every core (or as many threads as
// asked), a cancellation the test may set, and the progress kept for the
// test to read.

#include <mutex>
#include <thread>
#include <vector>

#include "core/WorkContext.h"

namespace rotafab::test {

class TestContext {
 public:
  explicit TestContext(unsigned threads = std::thread::hardware_concurrency())
      : executor_(threads), context_(executor_, cancellation_, [this](const core::Progress& p) {
          const std::lock_guard lock(mutex_);
          progress_.push_back(p);
        }) {}
  operator const core::WorkContext&() const { return context_; }  // NOLINT: passed where a context is asked for
  [[nodiscard]] const core::WorkContext& context() const { return context_; }
  core::Cancellation& cancellation() { return cancellation_; }
  // Every event so far, in order.
  [[nodiscard]] std::vector<core::Progress> progress() const {
    const std::lock_guard lock(mutex_);
    return progress_;
  }

 private:
  core::Executor executor_;
  core::Cancellation cancellation_;
  core::WorkContext context_;
  mutable std::mutex mutex_;
  std::vector<core::Progress> progress_;
};

// A context for calls whose progress no test reads: `nest(parts, options, context())`.
inline const core::WorkContext& context() {
  static core::Executor executor(std::thread::hardware_concurrency());
  static const core::Cancellation never;
  static const core::WorkContext shared(executor, never);
  return shared;
}

}  // namespace rotafab::test
