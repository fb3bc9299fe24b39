#include "devices/remote/RemoteDevice.h"

#include <fmt/format.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

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
  std::vector<char*> args;
  for (std::string& arg : argv_) args.push_back(arg.data());
  args.push_back(nullptr);
  const int spawned = ::posix_spawn(&child_, argv_[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(sockets[1]);
  if (spawned != 0) {
    ::close(sockets[0]);
    child_ = -1;
    throw DeviceFault(FaultKind::Disconnected,
                      fmt::format("{}: cannot start it: {}", argv_[0], std::strerror(spawned)));
  }
  pipe_ = std::make_unique<LinePipe>(sockets[0], ::dup(sockets[0]));
}

void RemoteDevice::stop() noexcept {
  if (child_ < 0) return;
  pipe_.reset();  // the helper's input ends: it disconnects and goes
  const auto deadline = Clock::now() + timeouts_.exit;
  int status = 0;
  while (::waitpid(child_, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      ::kill(child_, SIGKILL);
      ::waitpid(child_, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  child_ = -1;
}

nlohmann::json RemoteDevice::call(const nlohmann::json& request, std::chrono::milliseconds timeout,
                                  const std::function<void(const Progress&)>& progress,
                                  const core::Cancellation* cancel) {
  const std::string name = argv_[0];
  const auto gone = [&] {
    DeviceFault fault(FaultKind::Disconnected, fmt::format("{}: the helper ended", name));
    fault.laserOffConfirmed = false;
    return fault;
  };
  if (!pipe_ || !pipe_->writeLine(request.dump())) throw gone();
  auto deadline = Clock::now() + timeout;
  bool cancelSent = false;
  std::string line;
  for (;;) {
    if (cancel && cancel->cancelled() && !cancelSent) {
      // The helper's driver stops the machine and answers with its fault.
      pipe_->writeLine(nlohmann::json{{"op", "cancel"}}.dump());
      cancelSent = true;
      deadline = Clock::now() + timeouts_.stop;
    }
    if (Clock::now() > deadline) {
      throw DeviceFault(FaultKind::Timeout,
                        fmt::format("{}: no answer to {} within {} ms", name, request.value("op", "a request"),
                                    std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count()));
    }
    const LinePipe::Read read = pipe_->readLine(line, kTick);
    if (read == LinePipe::Read::Timeout) continue;
    if (read == LinePipe::Read::End) throw gone();
    nlohmann::json answer;
    try {
      answer = nlohmann::json::parse(line);
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
    }
    throw DeviceFault(FaultKind::Protocol, fmt::format("{}: an answer no helper gives: {}", name, line));
  }
}

std::string RemoteDevice::connect() {
  if (!pipe_) start();
  return call({{"op", "connect"}}, timeouts_.request).at("identity").get<std::string>();
}

void RemoteDevice::home() { call({{"op", "home"}}, timeouts_.home); }

void RemoteDevice::frame(const jobs::Toolpath& toolpath) {
  call({{"op", "frame"}, {"toolpath", toJson(toolpath)}}, timeouts_.home);
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

void RemoteDevice::disconnect() {
  if (!pipe_) return;
  try {
    call({{"op", "disconnect"}}, timeouts_.request);
  } catch (const DeviceFault&) {
  }
  stop();
}

}  // namespace rotafab::devices::remote
