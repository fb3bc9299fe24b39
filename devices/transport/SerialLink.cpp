#include "devices/transport/SerialLink.h"

#include <fmt/format.h>

namespace rotafab::devices {
namespace {

namespace asio = boost::asio;

// The Asio stream (serial_port or tcp::socket) behind a Link: each call runs
// its own io_context for at most the timeout, then cancels what is left.
template <typename Stream>
class AsioLink : public Link {
 public:
  AsioLink(std::string name, std::unique_ptr<asio::io_context> io, std::unique_ptr<Stream> stream)
      : name_(std::move(name)), io_(std::move(io)), stream_(std::move(stream)) {}
  ~AsioLink() override { AsioLink::close(); }

  void write(const std::string& bytes, Millis timeout) override {
    if (!stream_->is_open()) throw DeviceFault(FaultKind::Disconnected, name_ + ": the port is closed");
    std::optional<boost::system::error_code> result;
    asio::async_write(*stream_, asio::buffer(bytes),
                      [&](const boost::system::error_code& error, size_t) { result = error; });
    runFor(*io_, result, timeout, "writing");
  }

  std::optional<std::string> readLine(Millis timeout) override {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto newline = pending_.find('\n');
      if (newline != std::string::npos) {
        std::string line = pending_.substr(0, newline);
        pending_.erase(0, newline + 1);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        return line;
      }
      const auto left = std::chrono::duration_cast<Millis>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0 || !readMore(left)) return std::nullopt;
      if (pending_.size() > 1 << 16) {
        throw DeviceFault(FaultKind::Protocol, name_ + ": more than 64 KiB without a line ending");
      }
    }
  }

  std::optional<std::string> readSome(Millis timeout) override {
    if (pending_.empty() && !readMore(timeout)) return std::nullopt;
    return std::exchange(pending_, {});
  }

  void close() override {
    boost::system::error_code ignored;
    if (stream_ && stream_->is_open()) stream_->close(ignored);
  }

  [[nodiscard]] std::string name() const override { return name_; }

 private:
  // Appends what comes within `timeout` to pending_; false when nothing came.
  bool readMore(Millis timeout) {
    if (!stream_->is_open()) throw DeviceFault(FaultKind::Disconnected, name_ + ": the port is closed");
    char buffer[512];
    std::optional<boost::system::error_code> result;
    size_t got = 0;
    stream_->async_read_some(asio::buffer(buffer),
                             [&](const boost::system::error_code& error, size_t n) { result = error, got = n; });
    if (!runFor(*io_, result, timeout, nullptr)) return false;
    pending_.append(buffer, got);
    return true;
  }

  // Runs `io` until the operation sets `result` or `timeout` passes. Returns
  // false on a read timeout (what = nullptr); throws on a write timeout or an error.
  bool runFor(asio::io_context& io, std::optional<boost::system::error_code>& result, Millis timeout,
              const char* what) {
    io.restart();
    io.run_for(timeout);
    if (!result) {
      boost::system::error_code ignored;
      stream_->cancel(ignored);
      io.restart();
      io.run();                             // the cancelled handler
      if (result && !*result) return true;  // it completed after all
      if (!what) return false;
      throw DeviceFault(FaultKind::Timeout, fmt::format("{}: {} timed out after {} ms", name_, what, timeout.count()));
    }
    if (*result) {
      throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: {}", name_, result->message()));
    }
    return true;
  }

  std::string name_;
  std::unique_ptr<asio::io_context> io_;
  std::unique_ptr<Stream> stream_;
  std::string pending_;
};

}  // namespace

std::unique_ptr<Link> openSerialLink(const std::string& path, unsigned baud) {
  auto io = std::make_unique<asio::io_context>();
  auto port = std::make_unique<asio::serial_port>(*io);
  boost::system::error_code error;
  port->open(path, error);
  if (error) throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: cannot open it: {}", path, error.message()));
  port->set_option(asio::serial_port_base::baud_rate(baud), error);
  if (!error) port->set_option(asio::serial_port_base::character_size(8), error);
  if (!error) port->set_option(asio::serial_port_base::parity(asio::serial_port_base::parity::none), error);
  if (!error) port->set_option(asio::serial_port_base::stop_bits(asio::serial_port_base::stop_bits::one), error);
  if (!error) port->set_option(asio::serial_port_base::flow_control(asio::serial_port_base::flow_control::none), error);
  if (error)
    throw DeviceFault(FaultKind::Disconnected,
                      fmt::format("{}: cannot set {} baud 8N1: {}", path, baud, error.message()));
  return std::make_unique<AsioLink<asio::serial_port>>(path, std::move(io), std::move(port));
}

std::unique_ptr<Link> openTcpLink(const std::string& host, const std::string& port, Millis timeout) {
  auto io = std::make_unique<asio::io_context>();
  auto socket = std::make_unique<asio::ip::tcp::socket>(*io);
  const std::string name = host + ":" + port;
  boost::system::error_code error;
  asio::ip::tcp::resolver resolver(*io);
  const auto endpoints = resolver.resolve(host, port, error);
  if (error)
    throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: cannot resolve it: {}", name, error.message()));
  std::optional<boost::system::error_code> result;
  asio::async_connect(*socket, endpoints, [&](const boost::system::error_code& e, const auto&) { result = e; });
  io->run_for(timeout);
  if (!result)
    throw DeviceFault(FaultKind::Timeout, fmt::format("{}: no connection within {} ms", name, timeout.count()));
  if (*result)
    throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: cannot connect: {}", name, result->message()));
  return std::make_unique<AsioLink<asio::ip::tcp::socket>>(name, std::move(io), std::move(socket));
}

}  // namespace rotafab::devices
