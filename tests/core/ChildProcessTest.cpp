// A child program that aborts, hangs or fails comes back as a status, never
// taking the caller down; its input goes in whole and its output comes back
// whole; it starts with default signals in a process group of its own, and a
// cancel ends it at once.

#include "core/ChildProcess.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>
#include <thread>

#include "support/TestSupport.h"

namespace rotafab::core {
namespace {

using namespace std::chrono_literals;

ChildResult shell(const std::string& script, std::string_view input = {}, std::chrono::milliseconds timeout = 10s,
                  const Cancellation* cancellation = nullptr) {
  return runChild({"/bin/sh", "-c", script}, input, timeout, cancellation);
}

TEST(ChildProcess, InputGoesInAndOutputComesBackWhole) {
  const std::string big(3'000'000, 'x');  // larger than any pipe buffer, both ways
  const ChildResult result = shell("cat; printf end", big);
  EXPECT_EQ(result.status, ChildResult::Status::Finished);
  ASSERT_EQ(result.output.size(), big.size() + 3);
  EXPECT_EQ(result.output.substr(result.output.size() - 3), "end");
  EXPECT_EQ(result.output.find_first_not_of('x'), big.size());
}

TEST(ChildProcess, TheEnvironmentGetsWhatTheCallerAddsUnlessItHasItAlready) {
  ::setenv("ROTAFAB_TEST_SET", "caller", 1);
  const ChildResult result = runChild({"/bin/sh", "-c", "printf '%s %s' \"$ROTAFAB_TEST_SET\" \"$ROTAFAB_TEST_NEW\""},
                                      "", 10s, nullptr, {"ROTAFAB_TEST_SET=added", "ROTAFAB_TEST_NEW=added"});
  ::unsetenv("ROTAFAB_TEST_SET");
  ASSERT_EQ(result.status, ChildResult::Status::Finished);
  EXPECT_EQ(result.output, "caller added");
}

TEST(ChildProcess, AbortIsACrashWithItsSignal) {
  const ChildResult result = shell("printf partial; kill -ABRT $$");
  EXPECT_EQ(result.status, ChildResult::Status::Crashed);
  EXPECT_EQ(result.signal, SIGABRT);
  EXPECT_TRUE(result.output.empty()) << "a crashed child's output is not an answer";
}

TEST(ChildProcess, AFailedExitIsACrashWithItsStatus) {
  const ChildResult result = shell("printf partial; exit 3");
  EXPECT_EQ(result.status, ChildResult::Status::Crashed);
  EXPECT_EQ(result.signal, 0);
  EXPECT_EQ(result.exitCode, 3);
}

// The child's process id, which it wrote into `file`; and whether a process
// of that id is still there (a zombie would be).
bool stillThere(const std::filesystem::path& file) {
  std::ifstream in(file);
  pid_t pid = 0;
  in >> pid;
  EXPECT_GT(pid, 0) << "the child wrote no process id";
  return pid > 0 && (::kill(pid, 0) == 0 || errno != ESRCH);
}

TEST(ChildProcess, HangIsKilledAtTheTimeoutAndReaped) {
  test::TempDir dir;
  const auto pidFile = dir.path() / "pid";
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(shell("echo $$ > '" + pidFile.string() + "'; exec sleep 30", {}, 300ms).status,
            ChildResult::Status::TimedOut);
  EXPECT_FALSE(stillThere(pidFile));
  // A child that closed its output and still does not end.
  EXPECT_EQ(shell("exec >&-; echo $$ > '" + pidFile.string() + "'; exec sleep 30", {}, 300ms).status,
            ChildResult::Status::TimedOut);
  EXPECT_FALSE(stillThere(pidFile));
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
}

TEST(ChildProcess, ACancelKillsTheChildAtOnce) {
  test::TempDir dir;
  const auto pidFile = dir.path() / "pid";
  Cancellation cancellation;
  std::chrono::steady_clock::time_point cancelledAt;
  std::thread canceller([&] {
    std::this_thread::sleep_for(300ms);
    cancelledAt = std::chrono::steady_clock::now();
    cancellation.cancel();
  });
  EXPECT_THROW(shell("echo $$ > '" + pidFile.string() + "'; exec sleep 30", {}, 60s, &cancellation), Cancelled);
  const auto returnedAt = std::chrono::steady_clock::now();
  canceller.join();
  EXPECT_LT(returnedAt - cancelledAt, 500ms);
  EXPECT_FALSE(stillThere(pidFile)) << "the cancelled child is still there";
}

TEST(ChildProcess, TheChildHasOnlyItsThreeStandardDescriptors) {
  // One the caller opened without close-on-exec, as some libraries do.
  const int leaky = ::open("/dev/null", O_RDONLY);
  ASSERT_GE(leaky, 3);
  const ChildResult result = shell("cd /proc/self/fd && echo *");
  ::close(leaky);
  ASSERT_EQ(result.status, ChildResult::Status::Finished);
  // The shell's glob opens the folder itself: one more descriptor, its own.
  EXPECT_EQ(result.output.substr(0, 6), "0 1 2 ") << result.output;
  EXPECT_EQ(result.output.find(" " + std::to_string(leaky) + " "), std::string::npos) << result.output;
  EXPECT_LE(std::count(result.output.begin(), result.output.end(), ' '), 3) << result.output;
}

TEST(ChildProcess, AnExitStatusThatCannotBeHadIsNoAnswer) {
  // With SIGCHLD ignored the system reaps the child itself: its status is
  // lost, and what it wrote is not taken as a whole answer.
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGCHLD, &ignore, &previous);
  const ChildResult result = shell("printf partial; exit 1");
  ::sigaction(SIGCHLD, &previous, nullptr);
  EXPECT_EQ(result.status, ChildResult::Status::Crashed);
  EXPECT_TRUE(result.output.empty());
}

TEST(ChildProcess, StartsWithDefaultSignalsInAGroupOfItsOwn) {
  // The caller blocks SIGTERM and ignores SIGPIPE, as a command line that
  // waits for signals on a thread of its own does; the child must not.
  sigset_t term, before;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  ASSERT_EQ(::pthread_sigmask(SIG_BLOCK, &term, &before), 0);
  struct sigaction ignore {
  }, previous{};
  ignore.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ignore, &previous);
  const ChildResult terminated = shell("kill -TERM $$; sleep 5");
  const ChildResult piped = shell("kill -PIPE $$; sleep 5");
  // Field 5 of /proc/PID/stat: the process group.
  const ChildResult group = shell("read -r pid comm state ppid pgrp rest < /proc/self/stat; printf %s $pgrp");
  ::sigaction(SIGPIPE, &previous, nullptr);
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);

  EXPECT_EQ(terminated.status, ChildResult::Status::Crashed);
  EXPECT_EQ(terminated.signal, SIGTERM);
  EXPECT_EQ(piped.signal, SIGPIPE);
  ASSERT_EQ(group.status, ChildResult::Status::Finished);
  EXPECT_NE(group.output, std::to_string(::getpgrp())) << "a Ctrl-C at the terminal would reach the child";
}

TEST(ChildProcess, AProgramThatCannotBeStartedIsASystemError) {
  EXPECT_THROW(runChild({"/nonexistent/rotafab-no-such-helper"}, "", 1s), std::system_error);
  EXPECT_THROW(runChild({"rotafab-no-such-helper-on-the-path"}, "", 1s), std::system_error);
}

}  // namespace
}  // namespace rotafab::core
