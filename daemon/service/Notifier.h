#pragma once
// What the daemon tells the operator's phone or the lab's dashboard
// (docs/daemon.md, "Notifications"): each event, a JSON object, posted to
// every configured webhook (HTTP POST) and published over MQTT to a broker
// (libmosquitto), from a thread of its own, so that a slow or absent
// receiver never holds up the queue or a cut. Delivery is best effort: a
// receiver that does not answer within 5 s is logged (once, until it
// answers again) and skipped; events beyond 1,000 waiting are dropped, the
// oldest first, and the drop logged.

#include <spdlog/spdlog.h>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "daemon/service/NotifyConfig.h"

namespace rotafab::service {

class Notifier {
 public:
  Notifier(NotifyConfig config, std::shared_ptr<spdlog::logger> log);
  // Delivers what is waiting (within a few seconds), then stops.
  ~Notifier();
  Notifier(const Notifier&) = delete;
  Notifier& operator=(const Notifier&) = delete;

  // `event` has an "event" key (its kind); it is sent as it is.
  void send(nlohmann::json event);

 private:
  struct Mqtt;
  void deliver();
  void keepAlive();
  void post(const std::string& url, const std::string& body);
  void publish(const std::string& kind, const std::string& body);
  void failed(const std::string& receiver, const std::string& why);
  void answered(const std::string& receiver);

  NotifyConfig config_;
  std::shared_ptr<spdlog::logger> log_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<nlohmann::json> waiting_;
  bool stopping_ = false;
  std::chrono::steady_clock::time_point stopBy_{};
  std::vector<std::string> silent_;  // receivers whose failure is logged until they answer
  std::unique_ptr<Mqtt> mqtt_;
  std::thread thread_;
};

}  // namespace rotafab::service
