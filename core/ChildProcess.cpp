#include "core/ChildProcess.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <optional>
#include <system_error>

extern char** environ;

namespace rotafab::core {
namespace {

// Closes a descriptor when it goes out of scope.
class Descriptor {
 public:
  explicit Descriptor(int fd = -1) : fd_(fd) {}
  ~Descriptor() { reset(); }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  Descriptor(Descriptor&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  Descriptor& operator=(Descriptor&&) = delete;
  [[nodiscard]] int get() const { return fd_; }
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

[[noreturn]] void fail(int error, const std::string& what) {
  throw std::system_error(error, std::generic_category(), what);
}

// The input as an anonymous file: the child reads it at its own pace, and
// nothing here has to write and read two pipes at once.
Descriptor inputFile(std::string_view input) {
  Descriptor file(::memfd_create("rotafab-child-input", MFD_CLOEXEC));
  if (file.get() < 0) fail(errno, "memfd_create");
  size_t written = 0;
  while (written < input.size()) {
    const ssize_t n = ::write(file.get(), input.data() + written, input.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail(n < 0 ? errno : EIO, "writing the child's input");
    written += static_cast<size_t>(n);
  }
  if (::lseek(file.get(), 0, SEEK_SET) != 0) fail(errno, "lseek");
  return file;
}

class SpawnSetup {
 public:
  SpawnSetup(int input, int output) {
    posix_spawn_file_actions_init(&actions_);
    posix_spawn_file_actions_adddup2(&actions_, input, STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions_, output, STDOUT_FILENO);
    posix_spawn_file_actions_addopen(&actions_, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    // Nothing else of the caller's: a descriptor some library opened without
    // close-on-exec (a serial port, a pseudo-terminal) must not live on in it.
    posix_spawn_file_actions_addclosefrom_np(&actions_, STDERR_FILENO + 1);
    posix_spawnattr_init(&attributes_);
    sigset_t none, all;
    sigemptyset(&none);
    sigfillset(&all);
    // No signal blocked or ignored as the caller may have them (a caller that
    // ignores SIGPIPE, or blocks SIGINT for a thread that waits for it).
    posix_spawnattr_setsigmask(&attributes_, &none);
    posix_spawnattr_setsigdefault(&attributes_, &all);
    posix_spawnattr_setpgroup(&attributes_, 0);
    posix_spawnattr_setflags(&attributes_, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETPGROUP);
  }
  ~SpawnSetup() {
    posix_spawn_file_actions_destroy(&actions_);
    posix_spawnattr_destroy(&attributes_);
  }
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;
  const posix_spawn_file_actions_t* actions() const { return &actions_; }
  const posix_spawnattr_t* attributes() const { return &attributes_; }

 private:
  posix_spawn_file_actions_t actions_;
  posix_spawnattr_t attributes_;
};

// A started child: reaped once, and killed and reaped if whoever started it
// leaves early (an exception), so that no child runs on unwatched and no
// zombie is left.
class Child {
 public:
  explicit Child(pid_t pid) : pid_(pid) {}
  ~Child() { kill(); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // Its wait status once it has ended (-1 when it cannot be had: reaped
  // elsewhere), nothing while it runs.
  std::optional<int> poll() {
    if (reaped_) return status_;
    int status = 0;
    pid_t ended;
    while ((ended = ::waitpid(pid_, &status, WNOHANG)) < 0 && errno == EINTR) {
    }
    if (ended == 0) return std::nullopt;
    reaped_ = true;
    status_ = ended == pid_ ? status : -1;
    return status_;
  }
  void kill() {
    if (reaped_) return;
    ::kill(pid_, SIGKILL);
    int status = 0;
    pid_t ended;
    while ((ended = ::waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
    }
    reaped_ = true;
    status_ = ended == pid_ ? status : -1;
  }

 private:
  pid_t pid_;
  bool reaped_ = false;
  int status_ = -1;
};

}  // namespace

ChildResult runChild(const std::vector<std::string>& argv, std::string_view input, std::chrono::milliseconds timeout,
                     const Cancellation* cancellation, const std::vector<std::string>& environment) {
  if (argv.empty()) throw std::invalid_argument("runChild: no program");
  const Descriptor in = inputFile(input);
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) fail(errno, "pipe");
  Descriptor readEnd(fds[0]), writeEnd(fds[1]);
  ::fcntl(writeEnd.get(), F_SETPIPE_SZ, 1 << 20);  // fewer round trips for a large result; best effort

  std::vector<char*> args;
  for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  std::vector<char*> env;
  for (char** entry = environ; *entry; ++entry) env.push_back(*entry);
  for (const std::string& entry : environment) {
    const std::string name = entry.substr(0, entry.find('=') + 1);
    if (std::none_of(env.begin(), env.end(), [&](const char* e) { return std::string_view(e).starts_with(name); })) {
      env.push_back(const_cast<char*>(entry.c_str()));
    }
  }
  env.push_back(nullptr);
  pid_t pid = -1;
  {
    const SpawnSetup setup(in.get(), writeEnd.get());
    const bool path = argv[0].find('/') != std::string::npos;
    const int spawned =
        path ? ::posix_spawn(&pid, args[0], setup.actions(), setup.attributes(), args.data(), env.data())
             : ::posix_spawnp(&pid, args[0], setup.actions(), setup.attributes(), args.data(), env.data());
    if (spawned != 0) fail(spawned, "cannot start " + argv[0]);
  }
  Child child(pid);  // from here on, however this returns, the child is gone
  writeEnd.reset();  // the child's end: the read sees its end once the child is gone

  ChildResult result;
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
    pollfd waiting{readEnd.get(), POLLIN, 0};
    const int ready = ::poll(&waiting, 1, static_cast<int>(std::min<long long>(left.count(), 100)));
    if (ready <= 0) continue;  // a signal (EINTR) or the tick: look at the clock and the cancel again
    const ssize_t n = ::read(readEnd.get(), buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of output: the child closed its end
    result.output.append(buffer.data(), static_cast<size_t>(n));
  }
  readEnd.reset();
  // A child that closed its output may still not end: the same deadline and
  // cancel hold until it has.
  std::optional<int> status;
  while (!timedOut && !cancelled && !(status = child.poll())) {
    if (std::chrono::steady_clock::now() >= deadline) timedOut = true;
    if (cancellation && cancellation->cancelled()) cancelled = true;
    if (!timedOut && !cancelled) ::usleep(2000);
  }
  if (timedOut || cancelled) child.kill();
  if (cancelled) throw Cancelled();
  if (timedOut) {
    result.status = ChildResult::Status::TimedOut;
  } else if (*status >= 0 && WIFEXITED(*status) && WEXITSTATUS(*status) == 0) {
    result.status = ChildResult::Status::Finished;
  } else {
    // Unknown (-1: another part of the program reaped it, or SIGCHLD is
    // ignored) is no answer either.
    result.status = ChildResult::Status::Crashed;
    result.signal = *status >= 0 && WIFSIGNALED(*status) ? WTERMSIG(*status) : 0;
    result.exitCode = *status >= 0 && WIFEXITED(*status) ? WEXITSTATUS(*status) : -1;
    result.output.clear();
  }
  return result;
}

}  // namespace rotafab::core
