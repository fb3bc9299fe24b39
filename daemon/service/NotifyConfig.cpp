#include "daemon/service/NotifyConfig.h"

#include <fmt/format.h>

#include <stdexcept>
#include <string_view>

namespace rotafab::service {
namespace {

NotifyEndpoint endpoint(const std::string& url, std::string_view scheme, std::string_view defaultPort, bool path) {
  const std::string example = fmt::format("expected {}://HOST[:PORT]{}", scheme, path ? "[/PATH]" : "");
  if (!url.starts_with(std::string(scheme) + "://")) {
    throw std::invalid_argument(fmt::format("{}, found '{}'{}", example, url,
                                            url.starts_with("https://") || url.starts_with("mqtts://")
                                                ? " (TLS is not supported: a receiver on the lab's network, or a "
                                                  "relay beside the daemon)"
                                                : ""));
  }
  std::string rest = url.substr(scheme.size() + 3);
  NotifyEndpoint out;
  const size_t slash = rest.find('/');
  out.path = slash == std::string::npos ? "/" : rest.substr(slash);
  rest = rest.substr(0, slash);
  if (!path && out.path != "/") throw std::invalid_argument(fmt::format("{}, found '{}'", example, url));
  const size_t colon = rest.rfind(':');
  out.host = colon == std::string::npos ? rest : rest.substr(0, colon);
  out.port = colon == std::string::npos ? std::string(defaultPort) : rest.substr(colon + 1);
  const bool port = !out.port.empty() && out.port.size() <= 5 &&
                    out.port.find_first_not_of("0123456789") == std::string::npos && std::stoi(out.port) > 0 &&
                    std::stoi(out.port) < 65536;
  if (out.host.empty() || !port || out.host.find_first_of(" @") != std::string::npos) {
    throw std::invalid_argument(fmt::format("{}, found '{}'", example, url));
  }
  return out;
}

}  // namespace

NotifyEndpoint webhookEndpoint(const std::string& url) { return endpoint(url, "http", "80", true); }
NotifyEndpoint mqttEndpoint(const std::string& url) { return endpoint(url, "mqtt", "1883", false); }

}  // namespace rotafab::service
