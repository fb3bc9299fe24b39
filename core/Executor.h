#pragma once
// One pool of threads for all the parallel work of a caller (the command
// line, the daemon, a test), sized by that caller: the libraries never ask
// how many cores there are. parallelFor() shares the indices of a loop out
// among the pool and the calling thread, which works too: a parallelFor
// inside another (or two callers at once) cannot deadlock, since every
// caller can finish its own loop alone.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace rotafab::core {

class Executor {
 public:
  // `concurrency`: how many indices run at once, the calling thread's
  // included (at least 1); the pool starts concurrency - 1 threads (throws
  // std::system_error when the system has no more to give).
  explicit Executor(unsigned concurrency);
  ~Executor();  // waits for the threads; no loop may be running
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  [[nodiscard]] unsigned concurrency() const { return static_cast<unsigned>(threads_.size()) + 1; }

  // Runs body(i) for every i in [0, count) and returns when all have
  // finished. Indices are handed out in increasing order. When a body
  // throws, the indices above it that have not started are skipped, and once
  // the running ones are done the exception of the lowest index that threw
  // is rethrown: the same exception whatever the number of threads, for a
  // body that throws the same for the same index.
  void parallelFor(size_t count, const std::function<void(size_t)>& body);

 private:
  struct Loop;
  void work();
  void stopAll() noexcept;
  static void runIndices(Loop& loop);

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, finished_;
  std::deque<std::shared_ptr<Loop>> loops_;  // loops with indices left, oldest first
  bool stopping_ = false;
};

}  // namespace rotafab::core
