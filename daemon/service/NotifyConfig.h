#pragma once
// The daemon's `notify:` configuration (docs/daemon.md, "Notifications"),
// and its addresses taken apart: read by DaemonConfig, used by Notifier.

#include <string>
#include <vector>

namespace rotafab::service {

struct NotifyConfig {
  std::vector<std::string> webhooks;  // http://HOST[:PORT][/PATH]
  std::string mqtt;                   // mqtt://HOST[:PORT]; empty: none
  std::string topic = "rotafab";      // events go to TOPIC/EVENT: rotafab/load_sheet, rotafab/job_done, ...
  [[nodiscard]] bool any() const { return !webhooks.empty() || !mqtt.empty(); }
};

// An http:// or mqtt:// address taken apart; throws std::invalid_argument
// with what is wrong ("expected http://HOST[:PORT][/PATH]").
struct NotifyEndpoint {
  std::string host, port, path;
};
NotifyEndpoint webhookEndpoint(const std::string& url);
NotifyEndpoint mqttEndpoint(const std::string& url);

}  // namespace rotafab::service
