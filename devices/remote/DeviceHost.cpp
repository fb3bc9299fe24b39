#include "devices/remote/DeviceHost.h"

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "devices/remote/LinePipe.h"
#include "devices/remote/RemoteProtocol.h"

namespace rotafab::devices::remote {
namespace {

// What the reader hands the worker: the requests in order, and the end of the input.
struct Requests {
  std::mutex mutex;
  std::condition_variable arrived;
  std::deque<nlohmann::json> queue;
  bool ended = false;
};

std::string reply(const nlohmann::json& fields) {
  nlohmann::json out = fields;
  out["ok"] = true;
  return out.dump();
}

}  // namespace

void serveDevice(Device& device, int input, int output) {
  LinePipe pipe(input, output, false);
  Requests requests;
  // The cancellation of the run going on, each run its own.
  std::mutex runMutex;
  std::shared_ptr<core::Cancellation> running;
  bool inputEnded = false;
  const auto cancelRun = [&] {
    const std::lock_guard lock(runMutex);
    if (running) running->cancel();
  };
  // The reader: pause, resume and cancel act at once (the driver takes them
  // between its reads); everything else waits its turn.
  std::thread reader([&] {
    std::string line;
    for (;;) {
      const LinePipe::Read read = pipe.readLine(line, std::chrono::milliseconds(1000));
      if (read == LinePipe::Read::Timeout) continue;
      if (read == LinePipe::Read::End) break;
      nlohmann::json request;
      try {
        request = nlohmann::json::parse(line);
      } catch (const nlohmann::json::exception&) {
        pipe.writeLine(nlohmann::json{{"error", "not a request: " + line}}.dump());
        continue;
      }
      const std::string op = request.value("op", "");
      if (op == "pause") {
        device.pause();
      } else if (op == "resume") {
        device.resume();
      } else if (op == "cancel") {
        cancelRun();
      } else {
        const std::lock_guard lock(requests.mutex);
        requests.queue.push_back(std::move(request));
        requests.arrived.notify_one();
      }
    }
    {
      // Nobody is left to see the job: stop it safely.
      const std::lock_guard lock(runMutex);
      inputEnded = true;
      if (running) running->cancel();
    }
    const std::lock_guard lock(requests.mutex);
    requests.ended = true;
    requests.arrived.notify_one();
  });
  for (;;) {
    nlohmann::json request;
    {
      std::unique_lock lock(requests.mutex);
      requests.arrived.wait(lock, [&] { return requests.ended || !requests.queue.empty(); });
      if (requests.queue.empty()) break;
      request = std::move(requests.queue.front());
      requests.queue.pop_front();
    }
    const std::string op = request.value("op", "");
    try {
      if (op == "connect") {
        pipe.writeLine(reply({{"identity", device.connect()}}));
      } else if (op == "home") {
        device.home();
        pipe.writeLine(reply({}));
      } else if (op == "frame") {
        device.frame(toolpathOf(request.at("toolpath")));
        pipe.writeLine(reply({}));
      } else if (op == "run") {
        const jobs::Toolpath toolpath = toolpathOf(request.at("toolpath"));
        const auto cancel = std::make_shared<core::Cancellation>();
        {
          const std::lock_guard lock(runMutex);
          running = cancel;
          if (inputEnded) cancel->cancel();
        }
        struct Finished {
          std::mutex& mutex;
          std::shared_ptr<core::Cancellation>& running;
          ~Finished() {
            const std::lock_guard lock(mutex);
            running.reset();
          }
        } finished{runMutex, running};
        device.run(
            toolpath,
            [&](const Progress& p) {
              pipe.writeLine(nlohmann::json{{"progress", toJson(p)}}.dump());
            },
            *cancel);
        pipe.writeLine(reply({}));
      } else if (op == "status") {
        const DeviceStatus status = device.status();
        pipe.writeLine(reply({{"status", {{"state", status.state}, {"x", status.x}, {"y", status.y}}}}));
      } else if (op == "disconnect") {
        device.disconnect();
        pipe.writeLine(reply({}));
      } else {
        pipe.writeLine(nlohmann::json{{"error", "no such request: " + op}}.dump());
      }
    } catch (const DeviceFault& fault) {
      pipe.writeLine(nlohmann::json{{"fault", toJson(fault)}}.dump());
    } catch (const std::exception& error) {
      pipe.writeLine(nlohmann::json{{"error", error.what()}}.dump());
    }
  }
  reader.join();
  device.disconnect();
}

void serveError(const std::string& error, int input, int output) {
  LinePipe pipe(input, output, false);
  std::string line;
  for (;;) {
    const LinePipe::Read read = pipe.readLine(line, std::chrono::milliseconds(1000));
    if (read == LinePipe::Read::End) return;
    if (read == LinePipe::Read::Line) pipe.writeLine(nlohmann::json{{"error", error}}.dump());
  }
}

}  // namespace rotafab::devices::remote
