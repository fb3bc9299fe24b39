#include "core/Executor.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>

namespace rotafab::core {

struct Executor::Loop {
  const std::function<void(size_t)>* body = nullptr;
  size_t count = 0;
  std::atomic<size_t> next{0};
  // The lowest index that threw so far (max: none); indices above it are skipped.
  std::atomic<size_t> failedAt{std::numeric_limits<size_t>::max()};
  std::mutex errorMutex;
  std::exception_ptr error;  // of failedAt
  int helpers = 0;           // pool threads working on it (guarded by the executor's mutex)
};

Executor::Executor(unsigned concurrency) {
  try {
    for (unsigned i = 1; i < std::max(1u, concurrency); ++i) threads_.emplace_back([this] { work(); });
  } catch (...) {
    // No more threads to be had: let the ones started go, and say so.
    stopAll();
    throw;
  }
}

void Executor::stopAll() noexcept {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& thread : threads_) thread.join();
  threads_.clear();
}

Executor::~Executor() { stopAll(); }

void Executor::runIndices(Loop& loop) {
  for (;;) {
    const size_t i = loop.next.fetch_add(1, std::memory_order_relaxed);
    if (i >= loop.count || i > loop.failedAt.load(std::memory_order_relaxed)) return;
    try {
      (*loop.body)(i);
    } catch (...) {
      const std::lock_guard lock(loop.errorMutex);
      if (i < loop.failedAt.load(std::memory_order_relaxed)) {
        loop.failedAt.store(i, std::memory_order_relaxed);
        loop.error = std::current_exception();
      }
    }
  }
}

void Executor::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || !loops_.empty(); });
    if (stopping_) return;
    const std::shared_ptr<Loop> loop = loops_.front();
    ++loop->helpers;
    lock.unlock();
    runIndices(*loop);
    lock.lock();
    --loop->helpers;
    // No index left: later threads need not look at it.
    if (!loops_.empty() && loops_.front() == loop) loops_.pop_front();
    finished_.notify_all();
  }
}

void Executor::parallelFor(size_t count, const std::function<void(size_t)>& body) {
  if (count == 0) return;
  const auto loop = std::make_shared<Loop>();
  loop->body = &body;
  loop->count = count;
  if (!threads_.empty() && count > 1) {
    {
      const std::lock_guard lock(mutex_);
      loops_.push_back(loop);
    }
    wake_.notify_all();
  }
  runIndices(*loop);
  if (!threads_.empty() && count > 1) {
    std::unique_lock lock(mutex_);
    // No thread may join it after this; then wait for those on it.
    if (const auto it = std::find(loops_.begin(), loops_.end(), loop); it != loops_.end()) loops_.erase(it);
    finished_.wait(lock, [&] { return loop->helpers == 0; });
  }
  if (loop->error) std::rethrow_exception(loop->error);
}

}  // namespace rotafab::core
