// A child process that aborts, hangs or throws comes back as a status, never
// taking the caller down; its output comes back whole.

#include "geometry/IsolatedCall.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <thread>

namespace rotafab::geometry {
namespace {

using namespace std::chrono_literals;

TEST(IsolatedCall, OutputComesBackWhole) {
  const std::string big(3'000'000, 'x');  // larger than any pipe buffer
  const IsolatedResult result = runIsolated([&] { return big + "end"; }, 10s);
  EXPECT_EQ(result.status, IsolatedResult::Status::Finished);
  EXPECT_EQ(result.output.size(), big.size() + 3);
  EXPECT_EQ(result.output.substr(result.output.size() - 3), "end");
}

TEST(IsolatedCall, AbortIsACrashWithItsSignal) {
  const IsolatedResult result = runIsolated([]() -> std::string { std::abort(); }, 10s);
  EXPECT_EQ(result.status, IsolatedResult::Status::Crashed);
  EXPECT_EQ(result.signal, SIGABRT);
  EXPECT_TRUE(result.output.empty());
}

TEST(IsolatedCall, EscapingExceptionIsACrash) {
  const IsolatedResult result = runIsolated([]() -> std::string { throw std::runtime_error("boom"); }, 10s);
  EXPECT_EQ(result.status, IsolatedResult::Status::Crashed);
}

TEST(IsolatedCall, HangIsKilledAtTheTimeout) {
  const auto start = std::chrono::steady_clock::now();
  const IsolatedResult result = runIsolated(
      []() -> std::string {
        for (;;) ::pause();
      },
      300ms);
  EXPECT_EQ(result.status, IsolatedResult::Status::TimedOut);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
}

}  // namespace
}  // namespace rotafab::geometry
