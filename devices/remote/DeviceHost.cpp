#include "devices/remote/DeviceHost.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "devices/remote/LinePipe.h"
#include "devices/remote/RemoteProtocol.h"

namespace rotafab::devices::remote {
namespace {

using Clock = std::chrono::steady_clock;

// What the reader hands the worker: the requests in order, and the end of the input.
struct Requests {
  std::mutex mutex;
  std::condition_variable arrived;
  std::deque<nlohmann::json> queue;
  bool ended = false;
};

// The runs: the one going on (its id and cancellation), and the highest id
// cancelled so far, so that a cancel that comes before its run has started
// (or while it waits its turn) still stops it.
struct Runs {
  std::mutex mutex;
  long current = -1;
  std::shared_ptr<core::Cancellation> cancel;
  long cancelledUpTo = -1;
  bool inputEnded = false;

  void cancelRun(long id) {
    const std::lock_guard lock(mutex);
    cancelledUpTo = std::max(cancelledUpTo, id);
    if (cancel && current <= cancelledUpTo) cancel->cancel();
  }
  void endInput() {
    const std::lock_guard lock(mutex);
    inputEnded = true;
    if (cancel) cancel->cancel();
  }
  std::shared_ptr<core::Cancellation> start(long id) {
    const std::lock_guard lock(mutex);
    current = id;
    cancel = std::make_shared<core::Cancellation>();
    if (inputEnded || id <= cancelledUpTo) cancel->cancel();
    return cancel;
  }
  void finish() {
    const std::lock_guard lock(mutex);
    cancel.reset();
  }
};

nlohmann::json reply(long id, nlohmann::json fields = nlohmann::json::object()) {
  fields["ok"] = true;
  fields["id"] = id;
  return fields;
}

}  // namespace

void serveDevice(Device& device, int input, int output) {
  LinePipe pipe(input, output, false);
  Requests requests;
  Runs runs;
  std::atomic<long> busy{-1};  // the request being served, for the heartbeat
  // The reader: pause, resume and cancel act at once (the driver takes them
  // between its reads); everything else waits its turn. While a request is
  // served it says so every second, so that a hung helper is told from a
  // slow job.
  std::thread reader([&] {
    std::string line;
    auto lastWord = Clock::now();
    for (;;) {
      const LinePipe::Read read = pipe.readLine(line, std::chrono::milliseconds(250));
      if (read == LinePipe::Read::End) break;
      if (const long id = busy; id >= 0 && Clock::now() - lastWord > std::chrono::seconds(1)) {
        pipe.writeLine(nlohmann::json{{"alive", true}, {"id", id}}.dump());
        lastWord = Clock::now();
      }
      if (read == LinePipe::Read::Timeout) continue;
      nlohmann::json request;
      try {
        request = nlohmann::json::parse(line);
      } catch (const nlohmann::json::exception&) {
      }
      if (!request.is_object() || !request.contains("id") || !request.at("id").is_number_integer()) {
        pipe.writeLine(nlohmann::json{{"error", "not a request: " + line}}.dump());
        continue;
      }
      const std::string op = request.value("op", "");
      if (op == "pause") {
        device.pause();
      } else if (op == "resume") {
        device.resume();
      } else if (op == "cancel") {
        runs.cancelRun(request.at("id").get<long>());
      } else {
        const std::lock_guard lock(requests.mutex);
        requests.queue.push_back(std::move(request));
        requests.arrived.notify_one();
      }
    }
    runs.endInput();  // nobody is left to see the job: stop it safely
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
    const long id = request.at("id").get<long>();
    busy = id;
    try {
      if (op == "connect") {
        pipe.writeLine(reply(id, {{"identity", device.connect()}}).dump());
      } else if (op == "home") {
        device.home();
        pipe.writeLine(reply(id).dump());
      } else if (op == "frame" || op == "run") {
        // Each cancelled by its own `cancel` request: a frame too may light
        // the laser (a machine's frame_power).
        const jobs::Toolpath toolpath = toolpathOf(request.at("toolpath"));
        const auto cancel = runs.start(id);
        struct Finished {
          Runs& runs;
          ~Finished() { runs.finish(); }
        } finished{runs};
        if (op == "frame") {
          device.frame(toolpath, *cancel);
        } else {
          device.run(
              toolpath,
              [&](const Progress& p) {
                pipe.writeLine(nlohmann::json{{"progress", toJson(p)}, {"id", id}}.dump());
              },
              *cancel);
        }
        pipe.writeLine(reply(id).dump());
      } else if (op == "status") {
        const DeviceStatus status = device.status();
        pipe.writeLine(reply(id, {{"status", {{"state", status.state}, {"x", status.x}, {"y", status.y}}}}).dump());
      } else if (op == "stop") {
        pipe.writeLine(reply(id, {{"confirmed", device.stopSafely()}}).dump());
      } else if (op == "disconnect") {
        device.disconnect();
        pipe.writeLine(reply(id).dump());
      } else {
        pipe.writeLine(nlohmann::json{{"error", "no such request: " + op}, {"id", id}}.dump());
      }
    } catch (const DeviceFault& fault) {
      pipe.writeLine(nlohmann::json{{"fault", toJson(fault)}, {"id", id}}.dump());
    } catch (const std::exception& error) {
      pipe.writeLine(nlohmann::json{{"error", error.what()}, {"id", id}}.dump());
    }
    busy = -1;
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
    if (read != LinePipe::Read::Line) continue;
    nlohmann::json answer{{"error", error}};
    try {
      const auto request = nlohmann::json::parse(line);
      if (request.is_object() && request.contains("id")) answer["id"] = request.at("id");
    } catch (const nlohmann::json::exception&) {
    }
    pipe.writeLine(answer.dump());
  }
}

}  // namespace rotafab::devices::remote
