#include "devices/remote/RemoteDevice.h"

#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

extern char** environ;

namespace rotafab::devices::remote {
namespace {

using Clock = std::chrono::steady_clock;

// How often a wait looks at the cancel flag.
constexpr std::chrono::milliseconds kTick{100};

}  // namespace

RemoteDevice::RemoteDevice(std::vector<std::string> argv, RemoteTimeouts timeouts)
    : argv_(std::move(argv)), timeouts_(timeouts) {}

RemoteDevice::~RemoteDevice() { stop(); }

void RemoteDevice::start() {
  int sockets[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) {
    throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: no socket to it: {}", argv_[0], std::strerror(errno)));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, sockets[1], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, sockets[1], STDOUT_FILENO);
  // The helper leads a process group of its own, so that ending it ends
  // whatever it started too (a shell's children would otherwise live on,
  // holding our standard error open).
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attributes, 0);
  std::vector<char*> args;
  for (std::string& arg : argv_) args.push_back(arg.data());
  args.push_back(nullptr);
  const int spawned = ::posix_spawnp(&child_, argv_[0].c_str(), &actions, &attributes, args.data(), environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  ::close(sockets[1]);
  if (spawned != 0) {
    ::close(sockets[0]);
    child_ = -1;
    throw DeviceFault(FaultKind::Disconnected,
                      fmt::format("{}: cannot start it: {}", argv_[0], std::strerror(spawned)));
  }
  // Both ends close-on-exec: a later child (another helper, lp) must not
  // hold the socket open, or this helper would never see its input end.
  pipe_ = std::make_unique<LinePipe>(sockets[0], ::fcntl(sockets[0], F_DUPFD_CLOEXEC, 0));
  heardFromHelper_ = false;
}

void RemoteDevice::stop() noexcept {
  if (child_ < 0) return;
  pipe_.reset();  // the helper's input ends: it stops a run safely, disconnects and goes
  const auto deadline = Clock::now() + timeouts_.exit;
  int status = 0;
  while (::waitpid(child_, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      ::kill(-child_, SIGKILL);
      ::waitpid(child_, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(-child_, SIGKILL);  // what the helper left behind when it went
  child_ = -1;
}

nlohmann::json RemoteDevice::call(nlohmann::json request, std::chrono::milliseconds timeout,
                                  const std::function<void(const Progress&)>& progress,
                                  const core::Cancellation* cancel) {
  const std::string name = argv_[0], op = request.value("op", "a request");
  const long id = ++nextId_;
  request["id"] = id;
  // Something went wrong on this side: the helper is ended (a run in it
  // stops), and nobody can say the laser is off.
  const auto abandon = [&](FaultKind kind, const std::string& what) {
    stop();
    return DeviceFault(kind, fmt::format("{}: {}", name, what));
  };
  if (!pipe_ || !pipe_->writeLine(request.dump())) throw abandon(FaultKind::Disconnected, "the helper ended");
  auto deadline = Clock::now() + timeout;
  auto heard = Clock::now();
  bool cancelSent = false;
  std::string line;
  for (;;) {
    if (cancel && cancel->cancelled() && !cancelSent) {
      // The helper's driver stops the machine and answers with its fault.
      pipe_->writeLine(nlohmann::json{{"op", "cancel"}, {"id", id}}.dump());
      cancelSent = true;
      deadline = Clock::now() + timeouts_.stop;
      timeout = timeouts_.stop;
    }
    const auto now = Clock::now();
    if (now > deadline) {
      throw abandon(FaultKind::Timeout, fmt::format("no answer to {} within {} ms", op, timeout.count()));
    }
    // (Until the helper has said a word, it may still be starting: the request's timeout alone counts.)
    if (heardFromHelper_ && now - heard > timeouts_.silence) {
      throw abandon(FaultKind::Timeout, fmt::format("no word from the helper for {} ms", timeouts_.silence.count()));
    }
    const LinePipe::Read read = pipe_->readLine(line, kTick);
    if (read == LinePipe::Read::Timeout) continue;
    if (read == LinePipe::Read::End) throw abandon(FaultKind::Disconnected, "the helper ended");
    heard = Clock::now();
    heardFromHelper_ = true;
    nlohmann::json answer;
    try {
      answer = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception&) {
    }
    if (!answer.is_object() || !answer.contains("id")) {
      throw abandon(FaultKind::Protocol, "an answer no helper gives: " + line);
    }
    if (answer.at("id") != id || answer.contains("alive")) continue;  // a late word for an earlier request
    try {
      if (answer.contains("progress")) {
        if (progress) progress(progressOf(answer.at("progress")));
        continue;
      }
      if (answer.contains("fault")) throw faultOf(answer.at("fault"));
      if (answer.contains("error")) {
        throw DeviceFault(FaultKind::Protocol, fmt::format("{}: {}", name, answer.at("error").get<std::string>()));
      }
      if (answer.value("ok", false)) return answer;
    } catch (const nlohmann::json::exception&) {
    } catch (const DeviceFault&) {
      throw;  // the helper's own word: its driver has done what it could
    } catch (const std::exception& error) {
      throw abandon(FaultKind::Protocol, error.what());  // the progress callback
    }
    throw abandon(FaultKind::Protocol, "an answer no helper gives: " + line);
  }
}

std::string RemoteDevice::connect() {
  if (!pipe_) start();
  return call({{"op", "connect"}}, timeouts_.request).at("identity").get<std::string>();
}

void RemoteDevice::home() { call({{"op", "home"}}, timeouts_.home); }

void RemoteDevice::frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) {
  call({{"op", "frame"}, {"toolpath", toJson(toolpath)}}, timeouts_.home, nullptr, &cancel);
}

void RemoteDevice::run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
                       const core::Cancellation& cancel) {
  // No limit on the run itself: the driver in the helper has a timeout on every wait.
  call({{"op", "run"}, {"toolpath", toJson(toolpath)}}, std::chrono::hours(24 * 365), progress, &cancel);
}

void RemoteDevice::pause() {
  if (pipe_) pipe_->writeLine(nlohmann::json{{"op", "pause"}}.dump());
}

void RemoteDevice::resume() {
  if (pipe_) pipe_->writeLine(nlohmann::json{{"op", "resume"}}.dump());
}

DeviceStatus RemoteDevice::status() {
  const auto status = call({{"op", "status"}}, timeouts_.request).at("status");
  return {status.at("state").get<std::string>(), status.at("x").get<double>(), status.at("y").get<double>()};
}

bool RemoteDevice::stopSafely() noexcept {
  try {
    if (!pipe_) start();
    return call({{"op", "stop"}}, timeouts_.home).value("confirmed", false);
  } catch (...) {
    return false;  // the helper is gone: nothing can be said to the device
  }
}

void RemoteDevice::disconnect() {
  if (!pipe_) return;
  try {
    call({{"op", "disconnect"}}, timeouts_.request);
  } catch (const DeviceFault&) {
  }
  stop();
}

}  // namespace rotafab::devices::remote
