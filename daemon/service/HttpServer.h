#pragma once
// The daemon's API (docs/CONTRACT.md, "Daemon"; docs/API.md): JSON over HTTP/1.1 with
// Boost.Beast, on the Unix socket (mode 0600: the user who runs the daemon)
// and on any TCP listener configured (a bearer token, checked against the
// salted hashes of the configuration, whenever tokens are configured, and
// always beyond loopback). Every request has a time limit for its header
// and one for its body, a size limit, and a place among a limited number of
// connections; whatever is malformed, too large, too slow, unauthenticated
// or unknown gets a 4xx with {"error": "..."} and the daemon goes on serving.

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <memory>
#include <string>

#include "daemon/service/Service.h"

namespace spdlog {
class logger;
}

namespace rotafab::service {

struct HttpLimits {
  std::chrono::milliseconds header{10000};  // to receive a request's header
  std::chrono::milliseconds body{120000};   // to receive its body
  std::chrono::milliseconds idle{30000};    // between the requests of a kept-alive connection
  size_t headerBytes = 16 * 1024;
};

class HttpServer {
 public:
  HttpServer(boost::asio::io_context& io, Service& service, std::shared_ptr<spdlog::logger> log,
             HttpLimits limits = {});
  ~HttpServer();
  // Binds every listen address of the configuration; throws std::runtime_error naming the one that fails.
  void listen();
  // Stops accepting and closes every connection.
  void close();
  // The addresses bound, as "unix:PATH" and "tcp://HOST:PORT" (the port chosen when 0 was asked).
  [[nodiscard]] std::vector<std::string> addresses() const;

  struct Impl;  // the listeners and connections (HttpServer.cpp)

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace rotafab::service
