#include "cli/DaemonClient.h"

#include <fmt/format.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <optional>
#include <random>
#include <thread>

#include "core/ProgramFolders.h"

namespace rotafab::cli {
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using nlohmann::json;

namespace {

constexpr int kRequestSeconds = 120;  // a submission copies the mesh to the spool, synced
constexpr int kEventSeconds = 45;     // the daemon sends a keep-alive every 15 s

void setTimeout(int fd, int seconds) {
  timeval limit{seconds, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
}

std::string howToStart(const ServerAddress& address) {
  return address.unix
             ? fmt::format(
                   "no rotafabd answers on {}: start it with `rotafabd` (in another terminal, or as a "
                   "service), or give --server URL",
                   address.path)
             : fmt::format("no rotafabd answers at {}: is it running, and listening there?", address.describe());
}

// A connected socket of either kind, as one stream for Beast's synchronous calls.
class Connection {
 public:
  explicit Connection(const ServerAddress& address, int seconds) : address_(address) {
    try {
      if (address.unix) {
        unix_.emplace(io_);
        unix_->connect(asio::local::stream_protocol::endpoint(address.path));
        setTimeout(unix_->native_handle(), seconds);
      } else {
        tcp_.emplace(io_);
        asio::ip::tcp::resolver resolver(io_);
        asio::connect(*tcp_, resolver.resolve(address.host, address.port));
        setTimeout(tcp_->native_handle(), seconds);
      }
    } catch (const boost::system::system_error&) {
      throw DaemonUnreachable(howToStart(address));
    }
  }

  template <typename Message>
  void write(Message& message) {
    if (unix_) {
      http::write(*unix_, message);
    } else {
      http::write(*tcp_, message);
    }
  }
  template <typename Parser>
  void read(Parser& parser) {
    if (unix_) {
      http::read(*unix_, buffer_, parser);
    } else {
      http::read(*tcp_, buffer_, parser);
    }
  }
  template <typename Parser>
  void readHeader(Parser& parser) {
    if (unix_) {
      http::read_header(*unix_, buffer_, parser);
    } else {
      http::read_header(*tcp_, buffer_, parser);
    }
  }
  // Whatever comes next on the stream (after the header).
  size_t readSome(char* into, size_t size) {
    if (buffer_.size() > 0) {
      const size_t taken = asio::buffer_copy(asio::buffer(into, size), buffer_.data());
      buffer_.consume(taken);
      return taken;
    }
    return unix_ ? unix_->read_some(asio::buffer(into, size)) : tcp_->read_some(asio::buffer(into, size));
  }

 private:
  const ServerAddress& address_;
  asio::io_context io_;
  std::optional<asio::local::stream_protocol::socket> unix_;
  std::optional<asio::ip::tcp::socket> tcp_;
  beast::flat_buffer buffer_;
};

}  // namespace

std::string ServerAddress::describe() const { return unix ? "unix:" + path : fmt::format("http://{}:{}", host, port); }

ServerAddress serverAddress(const std::string& server, const std::string& token) {
  ServerAddress address;
  address.token = token;
  if (server.empty()) {
    address.path = core::defaultSocket(core::defaultStateDir()).string();
    return address;
  }
  if (server.starts_with("unix:")) {
    address.path = server.substr(5);
    if (address.path.empty()) throw core::UserError("--server unix:PATH: the socket's path is missing");
    return address;
  }
  std::string rest;
  if (server.starts_with("http://")) rest = server.substr(7);
  if (server.starts_with("tcp://")) rest = server.substr(6);
  while (rest.ends_with("/")) rest.pop_back();
  const size_t colon = rest.rfind(':');
  if (rest.empty() || colon == std::string::npos || colon == 0 || colon + 1 == rest.size()) {
    throw core::UserError(
        fmt::format("--server {}: expected unix:PATH or http://HOST:PORT (such as http://127.0.0.1:8730)", server));
  }
  address.unix = false;
  address.host = rest.substr(0, colon);
  address.port = rest.substr(colon + 1);
  return address;
}

HttpReply DaemonClient::request(const std::string& method, const std::string& target, const std::string& contentType,
                                const std::string& body) const {
  Connection connection(address_, kRequestSeconds);
  http::request<http::string_body> message(http::string_to_verb(method), target, 11);
  message.set(http::field::host, address_.unix ? "localhost" : address_.host);
  message.set(http::field::user_agent, "rotafab");
  if (!address_.token.empty()) message.set(http::field::authorization, "Bearer " + address_.token);
  if (!contentType.empty()) message.set(http::field::content_type, contentType);
  message.body() = body;
  message.keep_alive(false);
  message.prepare_payload();
  http::response_parser<http::string_body> parser;
  parser.body_limit(1u << 30);
  // A daemon that refuses a body (too large, a full disk) answers before
  // reading all of it and closes: its reply is read even when the rest of
  // the body could not be sent.
  std::optional<boost::system::system_error> unsent;
  try {
    connection.write(message);
  } catch (const boost::system::system_error& error) {
    unsent = error;
  }
  try {
    connection.read(parser);
  } catch (const boost::system::system_error& error) {
    throw DaemonUnreachable(fmt::format("rotafabd at {} did not answer {} {}: {}", address_.describe(), method, target,
                                        (unsent ? *unsent : error).code().message()));
  }
  HttpReply reply;
  reply.status = static_cast<int>(parser.get().result_int());
  reply.body = json::parse(parser.get().body(), nullptr, false);
  if (reply.body.is_discarded()) {
    throw core::UserError(fmt::format("{} answered {} with something that is not JSON: is it a rotafabd?",
                                      address_.describe(), reply.status));
  }
  if (reply.status >= 400) {
    throw DaemonRefused(reply.body.is_object() && reply.body.contains("error") && reply.body["error"].is_string()
                            ? reply.body["error"].get<std::string>()
                            : fmt::format("rotafabd answered {}", reply.status),
                        reply.status, reply.body);
  }
  return reply;
}

json DaemonClient::get(const std::string& target) const { return request("GET", target, "", "").body; }

json DaemonClient::post(const std::string& target, const json& body) const {
  return request("POST", target, "application/json", body.dump()).body;
}

json DaemonClient::postPatiently(const std::string& target, const json& body, double patience,
                                 const std::function<void(const DaemonRefused&)>& waiting) const {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(patience);
  bool told = false;
  for (;;) {
    try {
      return post(target, body);
    } catch (const DaemonRefused& refused) {
      const json& after = refused.body.is_object() ? refused.body.value("retry_after", json()) : json();
      if (!after.is_number() || std::chrono::steady_clock::now() >= until) throw;
      if (!told) waiting(refused);
      told = true;
      std::this_thread::sleep_for(std::chrono::duration<double>(std::clamp(after.get<double>(), 0.05, 5.0)));
    }
  }
}

json DaemonClient::upload(const std::string& target, const std::string& fileName, const std::string& bytes,
                          const std::vector<std::pair<std::string, std::string>>& fields) const {
  std::random_device random;
  const std::string boundary = fmt::format("rotafab-{:08x}{:08x}", random(), random());
  std::string body;
  for (const auto& [name, value] : fields) {
    body += fmt::format("--{}\r\nContent-Disposition: form-data; name=\"{}\"\r\n\r\n{}\r\n", boundary, name, value);
  }
  body += fmt::format(
      "--{}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{}\"\r\nContent-Type: "
      "application/octet-stream\r\n\r\n",
      boundary, fileName);
  body += bytes;
  body += fmt::format("\r\n--{}--\r\n", boundary);
  return request("POST", target, "multipart/form-data; boundary=" + boundary, body).body;
}

void DaemonClient::events(const std::string& target,
                          const std::function<bool(const std::string&, const json&)>& onEvent) const {
  Connection connection(address_, kEventSeconds);
  http::request<http::empty_body> message(http::verb::get, target, 11);
  message.set(http::field::host, address_.unix ? "localhost" : address_.host);
  if (!address_.token.empty()) message.set(http::field::authorization, "Bearer " + address_.token);
  http::response_parser<http::empty_body> parser;
  std::string pending;
  try {
    connection.write(message);
    connection.readHeader(parser);
    if (parser.get().result_int() != 200) {
      throw core::UserError(fmt::format("rotafabd refused the event stream ({})", parser.get().result_int()));
    }
    char chunk[4096];
    for (;;) {
      pending.append(chunk, connection.readSome(chunk, sizeof chunk));
      for (size_t end = pending.find("\n\n"); end != std::string::npos; end = pending.find("\n\n")) {
        const std::string block = pending.substr(0, end);
        pending.erase(0, end + 2);
        std::string type, data;
        size_t at = 0;
        while (at < block.size()) {
          const size_t lineEnd = std::min(block.find('\n', at), block.size());
          const std::string line = block.substr(at, lineEnd - at);
          if (line.starts_with("event: ")) type = line.substr(7);
          if (line.starts_with("data: ")) data += line.substr(6);
          at = lineEnd + 1;
        }
        if (type.empty()) continue;  // a comment: the keep-alive
        const json parsed = json::parse(data, nullptr, false);
        if (!parsed.is_discarded() && !onEvent(type, parsed)) return;
      }
    }
  } catch (const boost::system::system_error& error) {
    if (error.code() == asio::error::eof || error.code() == asio::error::connection_reset) {
      throw DaemonUnreachable(
          fmt::format("rotafabd at {} closed the event stream: it has stopped (its jobs say where "
                      "they were once it runs again)",
                      address_.describe()));
    }
    throw DaemonUnreachable(
        fmt::format("the event stream of rotafabd at {} ended: {}", address_.describe(), error.code().message()));
  }
}

}  // namespace rotafab::cli
