// The executor every layer's parallel work runs on (core/Executor.h): each
// index once, as many at once as asked, a loop inside a loop and two callers
// at once without a deadlock, the same exception whatever the threads, and
// a cancelled context's loop stopping.

#include "core/Executor.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "core/WorkContext.h"

namespace rotafab::core {
namespace {

TEST(Executor, RunsEveryIndexOnceOnAsManyThreadsAsAsked) {
  for (unsigned concurrency : {1u, 2u, 4u}) {
    Executor executor(concurrency);
    EXPECT_EQ(executor.concurrency(), concurrency);
    std::vector<std::atomic<int>> runs(1000);
    std::atomic<int> atOnce{0}, mostAtOnce{0};
    std::mutex mutex;
    std::set<std::thread::id> threads;
    executor.parallelFor(runs.size(), [&](size_t i) {
      const int now = ++atOnce;
      for (int seen = mostAtOnce; now > seen && !mostAtOnce.compare_exchange_weak(seen, now);) {
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      ++runs[i];
      {
        const std::lock_guard lock(mutex);
        threads.insert(std::this_thread::get_id());
      }
      --atOnce;
    });
    for (const auto& n : runs) EXPECT_EQ(n, 1);
    EXPECT_LE(mostAtOnce, static_cast<int>(concurrency));
    EXPECT_LE(threads.size(), concurrency);
    if (concurrency > 1) {
      EXPECT_GT(threads.size(), 1u) << "the pool's threads did not help";
    }
  }
}

TEST(Executor, ALoopInsideALoopAndTwoCallersAtOnceFinish) {
  Executor executor(2);
  std::atomic<int> inner{0};
  const auto nested = [&] {
    executor.parallelFor(8, [&](size_t) { executor.parallelFor(16, [&](size_t) { ++inner; }); });
  };
  std::thread other(nested);
  nested();
  other.join();
  EXPECT_EQ(inner, 2 * 8 * 16);
}

TEST(Executor, TheLowestIndexThatThrowsIsRethrownAndLaterIndicesAreSkipped) {
  for (unsigned concurrency : {1u, 3u}) {
    Executor executor(concurrency);
    std::atomic<size_t> highestRun{0};
    try {
      executor.parallelFor(10000, [&](size_t i) {
        for (size_t seen = highestRun; i > seen && !highestRun.compare_exchange_weak(seen, i);) {
        }
        if (i == 40 || i == 41 || i == 900) throw std::runtime_error("index " + std::to_string(i));
      });
      FAIL() << "nothing thrown";
    } catch (const std::runtime_error& error) {
      EXPECT_STREQ(error.what(), "index 40");
    }
    EXPECT_LT(highestRun, 1000u) << "indices after the failure kept running";
  }
}

TEST(WorkContext, ACancelledLoopStopsWithCancelled) {
  Executor executor(2);
  Cancellation cancellation;
  const WorkContext context(executor, cancellation);
  std::atomic<int> ran{0};
  EXPECT_THROW(context.parallelFor(100000,
                                   [&](size_t i) {
                                     if (i == 10) cancellation.cancel();
                                     ++ran;
                                   }),
               Cancelled);
  EXPECT_LT(ran, 1000);
  EXPECT_THROW(context.check(), Cancelled);
}

}  // namespace
}  // namespace rotafab::core
