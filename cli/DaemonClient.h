#pragma once
// The command line's side of the daemon's API (docs/API.md): HTTP/1.1
// requests over the Unix socket (by default) or TCP (--server URL --token
// T), each with a time limit, and the event stream.

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "core/UserError.h"

namespace rotafab::cli {

struct ServerAddress {
  bool unix = true;
  std::string path;        // the socket
  std::string host, port;  // TCP
  std::string token;
  [[nodiscard]] std::string describe() const;
};

// --server as given ("" is the default socket; unix:PATH, http://HOST:PORT, tcp://HOST:PORT).
// Throws core::UserError for a URL it cannot use.
ServerAddress serverAddress(const std::string& server, const std::string& token);

struct HttpReply {
  int status = 0;
  nlohmann::json body;
};

// Nobody answers at the address: one line that says so and how to start the daemon.
class DaemonUnreachable : public core::UserError {
 public:
  using core::UserError::UserError;
};

// The daemon refused the request (4xx, 5xx): its own error text, and the reply's other fields.
class DaemonRefused : public core::UserError {
 public:
  DaemonRefused(const std::string& message, int status, nlohmann::json body)
      : core::UserError(message), status(status), body(std::move(body)) {}
  int status;
  nlohmann::json body;
};

class DaemonClient {
 public:
  explicit DaemonClient(ServerAddress address) : address_(std::move(address)) {}

  // Throws DaemonUnreachable, and DaemonRefused with the daemon's own
  // error text for a refusal (4xx, 5xx).
  nlohmann::json get(const std::string& target) const;
  nlohmann::json post(const std::string& target, const nlohmann::json& body) const;
  // As post(), asked again while the daemon's refusal says when to (`retry_after`: its device is
  // being checked), for at most `patience` seconds; `waiting` is told the first time.
  nlohmann::json postPatiently(const std::string& target, const nlohmann::json& body, double patience,
                               const std::function<void(const DaemonRefused&)>& waiting) const;
  // A mesh as a multipart upload with the form's other fields.
  nlohmann::json upload(const std::string& target, const std::string& fileName, const std::string& bytes,
                        const std::vector<std::pair<std::string, std::string>>& fields) const;
  // Reads the event stream; `onEvent(type, data)` returns false to stop.
  void events(const std::string& target,
              const std::function<bool(const std::string&, const nlohmann::json&)>& onEvent) const;

 private:
  HttpReply request(const std::string& method, const std::string& target, const std::string& contentType,
                    const std::string& body) const;
  ServerAddress address_;
};

}  // namespace rotafab::cli
