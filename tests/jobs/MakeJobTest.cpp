// `make` as one call (jobs/MakeJob.h), as the command line and the daemon
// call it: cancelled in any phase of the bunny, it stops within a second,
// leaves no output folder and no thread behind.

#include "jobs/MakeJob.h"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <thread>

#include "core/UserError.h"
#include "support/TestContext.h"
#include "support/TestSupport.h"
#include "support/WorkshopRequest.h"

namespace rotafab::jobs {
namespace {

const std::filesystem::path kSource = ROTAFAB_SOURCE_DIR;

size_t threadsOfThisProcess() {
  size_t count = 0;
  for ([[maybe_unused]] const auto& task : std::filesystem::directory_iterator("/proc/self/task")) ++count;
  return count;
}

MakeRequest bunny(bool rows) { return test::workshopRequest(kSource / "examples/bunny.obj", rows); }

struct CancelPoint {
  std::string phase, step;
  bool rows;       // the quick layout, to reach the writing
  double seconds;  // after the step begins
};

TEST(MakeJob, CancelledInAnyPhaseStopsWithinASecondAndLeavesNothing) {
  const CancelPoint points[] = {
      {"import", "", false, 0.0},  {"geometry", "band decomposition", false, 0.0}, {"geometry", "labels", false, 0.05},
      {"nesting", "", false, 0.5}, {"nesting", "first layout", false, 0.3},        {"writing", "", true, 0.2}};
  for (const CancelPoint& point : points) {
    SCOPED_TRACE(point.phase + " " + point.step);
    test::TempDir dir;
    const auto out = dir.path() / "bunny-band";
    core::Executor executor(2);
    core::Cancellation cancellation;
    std::mutex mutex;
    std::condition_variable reached;
    bool there = false;
    const core::WorkContext context(executor, cancellation, [&](const core::Progress& p) {
      if (p.phase == point.phase && p.step == point.step) {
        const std::lock_guard lock(mutex);
        there = true;
        reached.notify_all();
      }
    });
    const size_t threadsBefore = threadsOfThisProcess();
    std::chrono::steady_clock::time_point cancelledAt;
    std::thread canceller([&] {
      std::unique_lock lock(mutex);
      reached.wait(lock, [&] { return there; });
      lock.unlock();
      std::this_thread::sleep_for(std::chrono::duration<double>(point.seconds));
      cancelledAt = std::chrono::steady_clock::now();
      cancellation.cancel();
    });
    bool stopped = false;
    try {
      makeJob(bunny(point.rows), out, context);
    } catch (const core::Cancelled&) {
      stopped = true;
    }
    const auto returnedAt = std::chrono::steady_clock::now();
    canceller.join();
    ASSERT_TRUE(stopped) << "the job ran to its end";
    EXPECT_LT(std::chrono::duration<double>(returnedAt - cancelledAt).count(), 1.0 * test::kPromisedDelayScale);
    EXPECT_FALSE(std::filesystem::exists(out)) << "an output folder was left";
    EXPECT_EQ(std::filesystem::directory_iterator(dir.path()), std::filesystem::directory_iterator())
        << "something was left beside it";
    EXPECT_EQ(threadsOfThisProcess(), threadsBefore) << "a thread of the work is still there";
  }
}

TEST(MakeJob, ErrorsNameTheMeshAndTheOptionAsTheCallerNamesIt) {
  MakeRequest request = bunny(true);
  request.fastener = 0.5;  // no band of the bunny has room for a 1/2 in hole
  request.size = 12.0;     // at the size the user fixed
  request.names = [](geometry::Parameter p) {
    return p == geometry::Parameter::Fastener ? "fastener" : p == geometry::Parameter::Size ? "size" : "other";
  };
  test::TempDir dir;
  try {
    makeJob(request, dir.path() / "out", test::context());
    FAIL() << "built";
  } catch (const core::UserError& error) {
    const std::string what = error.what();
    EXPECT_EQ(what.rfind(request.mesh.string() + ": ", 0), 0u) << what;
    EXPECT_NE(what.find("; size "), std::string::npos) << what;
    // (No smaller fastener is offered: at 12 in the bunny's numbers have no room at any.)
    EXPECT_NE(what.find(" or larger builds it as drawn (tried); other glues them"), std::string::npos) << what;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
}

}  // namespace
}  // namespace rotafab::jobs
