#include "geometry/IsolatedCall.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace rotafab::geometry {
namespace {

bool writeAll(int fd, const std::string& bytes) {
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

IsolatedResult runIsolated(const std::function<std::string()>& work, std::chrono::milliseconds timeout,
                           const core::Cancellation* cancellation) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  ::fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);  // fewer round trips for a large result; best effort
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::system_error(errno, std::generic_category(), "fork");
  }
  if (child == 0) {
    ::close(fds[0]);
    if (const int devNull = ::open("/dev/null", O_WRONLY); devNull >= 0) ::dup2(devNull, STDERR_FILENO);
    // Die plainly on a fault: handlers inherited from the parent (a sanitizer's,
    // a fuzzer's) would report the child's crash as the parent's.
    for (int fault : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGTRAP}) ::signal(fault, SIG_DFL);
    std::string output;
    try {
      output = work();
    } catch (...) {
      ::_exit(3);
    }
    // _exit: no atexit handlers, no destructors of the parent's objects.
    ::_exit(writeAll(fds[1], output) ? 0 : 4);
  }
  ::close(fds[1]);

  IsolatedResult result;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  bool timedOut = false, cancelled = false;
  std::vector<char> buffer(1 << 20);
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timedOut = true;
      break;
    }
    if (cancellation && cancellation->cancelled()) {
      cancelled = true;
      break;
    }
    pollfd waiting{fds[0], POLLIN, 0};
    const int ready = ::poll(&waiting, 1, static_cast<int>(std::min<long long>(left.count(), 100)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of output: the child closed its end
    result.output.append(buffer.data(), static_cast<size_t>(n));
  }
  ::close(fds[0]);
  if (timedOut || cancelled) ::kill(child, SIGKILL);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (cancelled) throw core::Cancelled();
  if (timedOut) {
    result.status = IsolatedResult::Status::TimedOut;
  } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    result.status = IsolatedResult::Status::Finished;
  } else {
    result.status = IsolatedResult::Status::Crashed;
    result.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    result.output.clear();
  }
  return result;
}

}  // namespace rotafab::geometry
