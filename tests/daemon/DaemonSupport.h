#pragma once
// The daemon as its tests run it: the built rotafabd as a process of its
// own, with its state and socket in a temporary folder (through
// XDG_STATE_HOME and XDG_RUNTIME_DIR, as a user's session sets them), the
// built `rotafab` as its client, and raw bytes on its socket for what no
// client would send.

#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "support/TestSupport.h"

extern char** environ;

namespace rotafab::test {

inline const std::string kCli = ROTAFAB_CLI;
inline const std::string kDaemon = ROTAFAB_DAEMON;
inline const std::filesystem::path kSource = ROTAFAB_SOURCE_DIR;

// Polls `done` every 20 ms for up to `seconds` (scaled under the sanitizers).
inline bool eventually(const std::function<bool()>& done, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds * kPromisedDelayScale);
  while (std::chrono::steady_clock::now() < until) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return done();
}

// Connects to a Unix socket; -1 when nobody listens.
inline int connectUnix(const std::filesystem::path& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", path.c_str());
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Sends `bytes` and reads until the daemon closes the connection (or `seconds` pass).
inline std::string exchange(int fd, const std::string& bytes, double seconds = 10) {
  timeval limit{static_cast<long>(seconds), static_cast<long>((seconds - static_cast<long>(seconds)) * 1e6)};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  std::string reply;
  char chunk[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, chunk, sizeof chunk, 0);
    if (n <= 0) break;
    reply.append(chunk, static_cast<size_t>(n));
  }
  return reply;
}

struct RawReply {
  int status = 0;
  nlohmann::json body;
  std::string text;
};

inline RawReply parseReply(const std::string& text) {
  RawReply reply;
  reply.text = text;
  if (text.size() > 12 && text.starts_with("HTTP/1.1 ")) reply.status = std::stoi(text.substr(9, 3));
  const size_t start = text.find("\r\n\r\n");
  if (start != std::string::npos) reply.body = nlohmann::json::parse(text.substr(start + 4), nullptr, false);
  return reply;
}

class Daemon {
 public:
  // `config`: the YAML of --config (none: the daemon's defaults).
  explicit Daemon(const std::filesystem::path& root, const std::string& config = "") : root_(root) {
    std::filesystem::create_directories(root_ / "state");
    std::filesystem::create_directories(root_ / "run");
    if (!config.empty()) configFile_ = TempDirWriter(root_, "rotafabd.yaml", config);
  }
  ~Daemon() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    // A failure that shows only in a loaded CI run is explained by what the daemon logged.
    if (::testing::Test::HasFailure() && std::filesystem::exists(log())) {
      const std::string text = readFile(log());
      std::fprintf(stderr, "--- the daemon's log (its last 8 KB) ---\n%s\n",
                   text.substr(text.size() > 8192 ? text.size() - 8192 : 0).c_str());
    }
  }
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  [[nodiscard]] std::filesystem::path stateDir() const { return root_ / "state/rotafab"; }
  [[nodiscard]] std::filesystem::path socket() const { return root_ / "run/rotafab/rotafabd.sock"; }
  [[nodiscard]] std::filesystem::path log() const { return root_ / "daemon.log"; }
  [[nodiscard]] std::string environment() const {
    return fmt::format("env XDG_STATE_HOME={} XDG_RUNTIME_DIR={} ", quoted(root_ / "state"), quoted(root_ / "run"));
  }

  // Starts the daemon and waits until it answers on its socket.
  void start(const std::vector<std::string>& extra = {}) {
    ASSERT_LE(pid_, 0) << "already running";
    std::vector<std::string> args{kDaemon};
    if (!configFile_.empty()) args.insert(args.end(), {"--config", configFile_.string()});
    args.insert(args.end(), extra.begin(), extra.end());
    pid_ = spawn(args);
    ASSERT_GT(pid_, 0);
    const bool serving = eventually(
        [&] {
          const int fd = connectUnix(socket());
          if (fd >= 0) ::close(fd);
          return fd >= 0 || exited();
        },
        20);
    ASSERT_TRUE(serving && !exited()) << "rotafabd did not start: " << readFile(log());
  }

  // Runs rotafabd with `args` to its end (a second instance, a bad config) and returns its status.
  int runToEnd(const std::vector<std::string>& args) {
    std::vector<std::string> all{kDaemon};
    all.insert(all.end(), args.begin(), args.end());
    const pid_t pid = spawn(all);
    int raw = 0;
    ::waitpid(pid, &raw, 0);
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  }

  void signal(int number) const { ::kill(pid_, number); }

  // Waits for the process to end; its exit status (128 + signal when killed), or -1 after `seconds`.
  int wait(double seconds = 30) {
    int status = -1;
    eventually([&] { return exited(&status); }, seconds);
    if (status != -1) pid_ = 0;
    return status;
  }

  void kill9() {
    signal(SIGKILL);
    wait();
  }

  CommandResult client(const std::string& args) const { return run(environment() + kCli + " " + args); }

  // The JSON the client prints with --json; a failed test when it fails.
  nlohmann::json clientJson(const std::string& args) const {
    const CommandResult r = client(args + " --json");
    EXPECT_EQ(r.status, 0) << args << ": " << r.err;
    return nlohmann::json::parse(r.out, nullptr, false);
  }

  // A request as raw bytes on the socket.
  RawReply raw(const std::string& bytes, double seconds = 10) const {
    const int fd = connectUnix(socket());
    if (fd < 0) return {};
    RawReply reply = parseReply(exchange(fd, bytes, seconds));
    ::close(fd);
    return reply;
  }
  RawReply get(const std::string& target) const {
    return raw(fmt::format("GET {} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n", target));
  }
  RawReply post(const std::string& target, const std::string& body) const {
    return raw(fmt::format(
        "POST {} HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: "
        "{}\r\n\r\n{}",
        target, body.size(), body));
  }
  nlohmann::json job(long long id) const { return get(fmt::format("/api/jobs/{}", id)).body; }

  // Waits until job `id` satisfies `condition`; the job as it was last seen.
  nlohmann::json waitForJob(long long id, const std::function<bool(const nlohmann::json&)>& condition,
                            double seconds = 60) const {
    nlohmann::json last;
    eventually(
        [&] {
          last = job(id);
          return last.is_object() && condition(last);
        },
        seconds);
    return last;
  }

 private:
  static std::filesystem::path TempDirWriter(const std::filesystem::path& root, const std::string& name,
                                             const std::string& text) {
    const auto file = root / name;
    std::ofstream(file) << text;
    return file;
  }

  pid_t spawn(const std::vector<std::string>& args) const {
    std::vector<std::string> env;
    for (char** e = environ; *e; ++e) {
      const std::string entry = *e;
      if (!entry.starts_with("XDG_STATE_HOME=") && !entry.starts_with("XDG_RUNTIME_DIR=")) env.push_back(entry);
    }
    env.push_back("XDG_STATE_HOME=" + (root_ / "state").string());
    env.push_back("XDG_RUNTIME_DIR=" + (root_ / "run").string());
    std::vector<char*> argv, envp;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    for (const auto& e : env) envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log().c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log().c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    pid_t pid = 0;
    const int failed = posix_spawn(&pid, args[0].c_str(), &actions, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    return failed == 0 ? pid : -1;
  }

  bool exited(int* status = nullptr) const {
    if (pid_ <= 0) return true;
    int raw = 0;
    if (::waitpid(pid_, &raw, WNOHANG) != pid_) return false;
    if (status) *status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
    const_cast<Daemon*>(this)->pid_ = 0;
    return true;
  }

  std::filesystem::path root_, configFile_;
  pid_t pid_ = 0;
};

}  // namespace rotafab::test
