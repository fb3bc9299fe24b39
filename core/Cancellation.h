#pragma once
// Stopping long work from outside it: Ctrl-C, a daemon's cancel request, a
// test. The one who may stop the work holds a Cancellation and calls cancel()
// from any thread; the work is handed it by reference (WorkContext) and
// checks it in every long loop, often enough to stop within 100 ms. Checking
// costs one atomic load; what was written before the cancel (why it was
// cancelled) is seen by the one who sees the cancel.

#include <atomic>
#include <stdexcept>

namespace rotafab::core {

// Thrown by work that stopped because it was cancelled. Not an error of the
// input: the caller reports it as the user's choice.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

class Cancellation {
 public:
  Cancellation() = default;
  Cancellation(const Cancellation&) = delete;
  Cancellation& operator=(const Cancellation&) = delete;

  void cancel() noexcept { cancelled_.store(true, std::memory_order_release); }
  [[nodiscard]] bool cancelled() const noexcept { return cancelled_.load(std::memory_order_acquire); }
  // Throws Cancelled once cancel() has been called.
  void check() const {
    if (cancelled()) throw Cancelled();
  }

 private:
  std::atomic<bool> cancelled_{false};
};

}  // namespace rotafab::core
