// rotafabd: the fabrication daemon (docs/CONTRACT.md, "Daemon"). Wiring only: the
// configuration, the state directory's lock, the logs, the signals; the
// queue is daemon/service/Service.h, the API daemon/service/HttpServer.h.

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/sinks/rotating_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/file.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <random>

#include "core/ExitCode.h"
#include "daemon/service/DaemonConfig.h"
#include "daemon/service/HttpServer.h"
#include "daemon/service/Service.h"
#include "profiles/Profiles.h"
#include "toolpath/AtomicFile.h"

namespace {

using namespace rotafab;
namespace fs = std::filesystem;

// One daemon per state directory: an exclusive lock on a file in it, held
// while the process lives (the kernel drops it on any death, kill -9 too).
int lockStateDir(const fs::path& stateDir) {
  const fs::path file = stateDir / "rotafabd.lock";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0)
    throw std::runtime_error(fmt::format("{}: cannot open the lock file: {}", file.string(), std::strerror(errno)));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = {};
    const ssize_t got = ::pread(fd, pid, sizeof pid - 1, 0);
    ::close(fd);
    throw std::runtime_error(fmt::format(
        "another rotafabd{} already runs on the state directory {}; stop it first, or "
        "give this one another state_dir in its --config",
        got > 0 ? fmt::format(" (pid {})", std::string(pid, std::strcspn(pid, "\n"))) : "", stateDir.string()));
  }
  const std::string text = fmt::format("{}\n", ::getpid());
  if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, text.data(), text.size(), 0) < 0) {
    // The pid is only for the message of a second daemon.
  }
  return fd;
}

std::shared_ptr<spdlog::logger> makeLogger(const fs::path& stateDir) {
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  console->set_pattern("%H:%M:%S %^%l%$ %v");
  auto file = std::make_shared<spdlog::sinks::rotating_file_sink_mt>((stateDir / "rotafabd.log").string(), 5u << 20, 3);
  file->set_pattern("%Y-%m-%d %H:%M:%S.%e %l %v");
  auto log = std::make_shared<spdlog::logger>("rotafabd", spdlog::sinks_init_list{console, file});
  log->set_level(spdlog::level::info);
  log->flush_on(spdlog::level::info);
  return log;
}

// The state is the daemon user's alone, whatever the umask it was started
// with: every job's owner, file and options are in it. Files and folders
// made from here on (umask 077) are 0600 and 0700 (SQLite's write-ahead log and shared
// memory too, which take the database's mode); what an earlier version
// left readable is made private, the folder first.
void keepStatePrivate(const fs::path& stateDir) {
  ::chmod(stateDir.c_str(), 0700);
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(stateDir, error)) {
    // (Not into the spool: a planned folder's files are hard links to the submitter's own.)
    if (entry.is_regular_file(error)) ::chmod(entry.path().c_str(), 0600);
  }
}

int serve(const service::DaemonConfig& config) {
  ::umask(0077);
  std::error_code error;
  fs::create_directories(config.stateDir, error);
  if (error) {
    fmt::print(stderr, "error: {}: cannot create the state directory: {}\n", config.stateDir.string(), error.message());
    return core::kUserError;
  }
  keepStatePrivate(config.stateDir);
  int lock = -1;
  try {
    lock = lockStateDir(config.stateDir);
  } catch (const std::exception& refused) {
    fmt::print(stderr, "error: {}\n", refused.what());
    return core::kUserError;
  }
  auto log = makeLogger(config.stateDir);
  boost::asio::io_context io(1);
  // Signals are taken by the io_context before any other thread starts, so that none of them gets one.
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  service::Service queue(io, config, log);
  try {
    queue.start();
  } catch (const std::exception& failed) {
    log->error("{}", failed.what());
    ::close(lock);
    return core::kUserError;
  }
  service::HttpLimits limits;
  limits.header = std::chrono::milliseconds(static_cast<long>(config.headerTimeout * 1000));
  limits.body = std::chrono::milliseconds(static_cast<long>(config.bodyTimeout * 1000));
  service::HttpServer server(io, queue, log, limits);
  try {
    server.listen();
  } catch (const std::exception& failed) {
    log->error("{}", failed.what());
    queue.shutdown("it could not listen", [] {});
    ::close(lock);
    return core::kUserError;
  }
  nlohmann::json where{{"pid", ::getpid()}, {"listen", server.addresses()}};
  try {
    jobs::writeFileAtomically(config.stateDir / "rotafabd.json", where.dump(2) + "\n");
  } catch (const std::exception& failed) {
    // (A full disk: the daemon serves all the same; `rotafab dashboard` needs --url.)
    log->error("{}", failed.what());
  }
  log->info("rotafabd serving on {}; state in {}; {} device{}", fmt::join(server.addresses(), ", "),
            config.stateDir.string(), config.devices.size(), config.devices.size() == 1 ? "" : "s");
  int stopSignal = 0;
  std::function<void(const boost::system::error_code&, int)> onSignal = [&](const boost::system::error_code& failed,
                                                                            int number) {
    if (failed) return;
    if (stopSignal == 0) {
      stopSignal = number;
      log->info("{}: stopping every device safely, then exiting", number == SIGTERM ? "SIGTERM" : "SIGINT");
      server.close();
      queue.shutdown(number == SIGTERM ? "SIGTERM" : "SIGINT", [&io] { io.stop(); });
    } else {
      log->warn("still stopping the devices safely; the daemon exits once their lasers are off");
    }
    signals.async_wait(onSignal);
  };
  signals.async_wait(onSignal);
  io.run();
  log->info("rotafabd stopped");
  std::error_code ignored;
  fs::remove(config.stateDir / "rotafabd.json", ignored);
  ::close(lock);
  return core::kSuccess;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rotafabd: the fabrication daemon, which keeps the job queue and drives the cutters"};
  app.set_version_flag("--version", "rotafabd 0.1.0");
  std::string configFile, token;
  app.add_option("--config", configFile,
                 "YAML configuration: state_dir, store (sqlite, or postgresql://USER@HOST:PORT/DB), listen, devices, "
                 "tokens (docs/CONTRACT.md, \"Daemon\"; every key optional)")
      ->check(CLI::ExistingFile);
  app.add_option("--hash-token", token, "Print the salted hash of TOKEN for the configuration's tokens, and exit");
  app.footer(
      "With no configuration: state in $XDG_STATE_HOME/rotafab (else ~/.local/state/rotafab), one simulated GRBL\n"
      "(laser1, sim:grbl, 100 times faster than the machine), the Unix socket $XDG_RUNTIME_DIR/rotafab/rotafabd.sock.\n"
      "SIGTERM or Ctrl-C stops every device safely (laser off), records running jobs as interrupted, and exits.\n\n"
      "Examples:\n"
      "  rotafabd\n"
      "  rotafab submit examples/cube.obj --structure band      # from another terminal\n"
      "  rotafabd --config /etc/rotafab/rotafabd.yaml\n"
      "  rotafabd --hash-token s3cret                            # for tokens: [{name: alice, hash: ...}]");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);
    fmt::print(stderr, "error: {}\nRun `rotafabd --help` for usage.\n", error.what());
    return rotafab::core::kUsageError;
  }
  if (!token.empty()) {
    std::random_device random;
    fmt::print("{}\n", rotafab::service::hashToken(token, fmt::format("{:08x}{:08x}", random(), random())));
    return 0;
  }
  try {
    const auto config =
        configFile.empty() ? rotafab::service::defaultConfig() : rotafab::service::loadConfig(configFile);
    return serve(config);
  } catch (const rotafab::service::ConfigError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return rotafab::core::kUserError;
  } catch (const std::exception& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return rotafab::core::kUserError;
  }
}
