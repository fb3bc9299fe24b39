// How soon a cancel stops `make` (jobs/MakeJob.h) on the bunny: the time
// from Cancellation::cancel() to makeJob() returning with core::Cancelled,
// cancelling at many moments in each phase (a delay after the phase's first
// progress event). The target: every long loop sees a cancel within 100 ms.
//
//   build/rotafab_cancel_bench [TRIES]   (default 5 per moment; ONLY="nesting first layout 5"
//                                          runs that moment alone, e.g. under perf)

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "jobs/MakeJob.h"

namespace {

using namespace rotafab;
using Clock = std::chrono::steady_clock;

struct Moment {
  const char* phase;
  const char* step;
  double after;  // seconds after the step's first event
  bool rows;     // the quick layout, to reach the writing soon
};

// One make, cancelled `after` seconds into `step`: seconds from the cancel to the return.
double latency(const Moment& moment, const std::filesystem::path& out) {
  const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  jobs::MakeRequest request;
  request.mesh = std::filesystem::path(ROTAFAB_SOURCE_DIR) / "examples/bunny.obj";
  request.machine = profiles::findMachine(catalogue, "workshop-32x18");
  request.material = profiles::findMaterial(catalogue, "posterboard");
  request.rows = moment.rows;
  core::Executor executor(2);
  core::Cancellation cancellation;
  std::mutex mutex;
  std::condition_variable reached;
  bool there = false;
  const core::WorkContext context(executor, cancellation, [&](const core::Progress& p) {
    if (p.phase == moment.phase && p.step == moment.step) {
      const std::lock_guard lock(mutex);
      there = true;
      reached.notify_all();
    }
  });
  Clock::time_point cancelledAt;
  std::thread canceller([&] {
    std::unique_lock lock(mutex);
    reached.wait(lock, [&] { return there; });
    lock.unlock();
    std::this_thread::sleep_for(std::chrono::duration<double>(moment.after));
    cancelledAt = Clock::now();
    cancellation.cancel();
  });
  try {
    jobs::makeJob(request, out, context);
  } catch (const core::Cancelled&) {
  }
  const auto returned = Clock::now();
  canceller.join();
  return std::chrono::duration<double>(returned - cancelledAt).count();
}

}  // namespace

int main(int argc, char** argv) {
  const int tries = argc > 1 ? std::atoi(argv[1]) : 5;
  const auto out = std::filesystem::temp_directory_path() / "rotafab-cancel-bench";
  const Moment moments[] = {
      {"geometry", "band decomposition", 0.0, false},
      {"geometry", "labels", 0.02, false},
      {"nesting", "", 0.5, false},
      {"nesting", "", 4, false},
      {"nesting", "first layout", 0.5, false},
      {"nesting", "first layout", 5, false},
      {"nesting", "first layout", 20, false},
      {"writing", "", 0.3, true},
  };
  fmt::print("{:<32} {:>8} {:>8} {:>8}\n", "cancelled", "median", "max", "ms");
  const char* only = std::getenv("ONLY");
  for (const Moment& moment : moments) {
    if (only && fmt::format("{} {} {}", moment.phase, moment.step, moment.after) != only) continue;
    std::vector<double> ms;
    for (int i = 0; i < tries; ++i) {
      // Spread the moments: each try a little later than the one before.
      Moment m = moment;
      m.after += 0.013 * i;
      ms.push_back(1000 * latency(m, out));
    }
    std::sort(ms.begin(), ms.end());
    fmt::print("{:<32} {:>8.1f} {:>8.1f}\n", fmt::format("{} {} +{}s", moment.phase, moment.step, moment.after),
               ms[ms.size() / 2], ms.back());
  }
  std::filesystem::remove_all(out);
}
