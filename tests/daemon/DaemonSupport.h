#pragma once
// The daemon as its tests run it: the built rotafabd as a process of its
// own, with its state and socket in a temporary folder (through
// XDG_STATE_HOME and XDG_RUNTIME_DIR, as a user's session sets them), the
// built `rotafab` as its client, and raw bytes on its socket for what no
// client would send.

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
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
  [[nodiscard]] pid_t pid() const { return pid_; }

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

struct HttpReply {
  int status = 0;
  std::string head, body;
  [[nodiscard]] std::string header(const std::string& name) const {
    const std::string key = "\r\n" + name + ": ";
    const size_t at = head.find(key);
    if (at == std::string::npos) return "";
    const size_t start = at + key.size();
    return head.substr(start, head.find("\r\n", start) - start);
  }
};

// A connection to 127.0.0.1:port; -1 when refused.
inline int connectTcp(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// One request on a new TCP connection to 127.0.0.1:port.
inline HttpReply overTcp(int port, const std::string& method, const std::string& target,
                         const std::string& extraHeaders = "", const std::string& body = "") {
  const int fd = connectTcp(port);
  if (fd < 0) return {};
  const std::string text = rotafab::test::exchange(
      fd, fmt::format("{} {} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\n{}Content-Length: {}\r\n\r\n{}",
                      method, target, port, extraHeaders, body.size(), body));
  ::close(fd);
  HttpReply reply;
  if (text.starts_with("HTTP/1.1 ")) reply.status = std::stoi(text.substr(9, 3));
  const size_t split = text.find("\r\n\r\n");
  reply.head = text.substr(0, split);
  if (split != std::string::npos) reply.body = text.substr(split + 4);
  return reply;
}

// The port of the daemon's loopback TCP listener, as rotafabd.json records
// it (written just after the socket answers: waited for).
inline int pagePort(const Daemon& daemon) {
  int port = 0;
  eventually(
      [&] {
        const nlohmann::json where =
            nlohmann::json::parse(readFile(daemon.stateDir() / "rotafabd.json"), nullptr, false);
        if (!where.is_object()) return false;
        for (const nlohmann::json& address : where["listen"]) {
          const std::string text = address.get<std::string>();
          if (text.starts_with("tcp://127.0.0.1:")) port = std::stoi(text.substr(16));
        }
        return port > 0;
      },
      10);
  return port;
}

// A loopback port nobody listens on now, for a server started after (a daemon again, a broker).
inline int freePort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t size = sizeof address;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  ::close(fd);
  return ntohs(address.sin_port);
}

// The configuration's one device: a simulated GRBL diode laser running at
// `speed` times real time, whose laser's changes ("on", "off") are written to `witness`.
inline std::string witnessedLaser(double speed, const std::filesystem::path& witness) {
  return fmt::format("devices: [{{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed={}&witness={}\"}}]\n",
                     speed, witness.string());
}

// The `make` output folder of an example for the default device's bed
// (grbl-diode-400), in a folder that lasts the whole program.
inline std::filesystem::path plannedExample(const std::string& example) {
  static TempDir folder;
  const std::filesystem::path out = folder.path() / std::filesystem::path(example).stem();
  const CommandResult r = run(kCli + " make " + quoted(kSource / "examples" / example) +
                              " --structure band --machine grbl-diode-400 --evaluations 1 --out " + quoted(out));
  EXPECT_EQ(r.status, 0) << r.err;
  return out;
}

// Three sheets, made once for the whole program.
inline const std::filesystem::path& threeSheets() {
  static const std::filesystem::path made = plannedExample("soccer-ball.obj");
  return made;
}

inline std::string state(const nlohmann::json& job) { return job.is_object() ? job.value("state", "") : ""; }

// Submits the three sheets, starts them once planned, and returns the job's
// number once its cut has reached its third stroke (an empty id on failure).
inline long long cuttingThreeSheets(Daemon& daemon) {
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  EXPECT_EQ(state(daemon.waitForJob(id, [](const nlohmann::json& j) { return state(j) == "ready"; })), "ready");
  EXPECT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
  const nlohmann::json cutting = daemon.waitForJob(
      id, [](const nlohmann::json& j) { return j.contains("progress") && j["progress"]["stroke"] >= 3; });
  EXPECT_GE(cutting.value("/progress/stroke"_json_pointer, 0), 3) << cutting.dump();
  return ::testing::Test::HasFailure() ? 0 : id;
}

}  // namespace rotafab::test
