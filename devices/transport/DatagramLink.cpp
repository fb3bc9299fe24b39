#include "devices/transport/DatagramLink.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

namespace rotafab::devices {
namespace {

namespace asio = boost::asio;
using asio::ip::udp;

}  // namespace

std::unique_ptr<DatagramLink> DatagramLink::open(const std::string& host, uint16_t port, uint16_t localPort) {
  std::unique_ptr<DatagramLink> link(new DatagramLink);
  link->name_ = fmt::format("{}:{}", host, port);
  link->io_ = std::make_unique<asio::io_context>();
  boost::system::error_code error;
  // A name looked up within a bound (a dead DNS server or mDNS can take long).
  udp::resolver resolver(*link->io_);
  std::optional<boost::system::error_code> resolved;
  udp::resolver::results_type found;
  resolver.async_resolve(udp::v4(), host, std::to_string(port),
                         [&](const boost::system::error_code& e, udp::resolver::results_type results) {
                           resolved = e, found = std::move(results);
                         });
  link->io_->run_for(std::chrono::seconds(5));
  if (!resolved) {
    resolver.cancel();
    link->io_->restart();
    link->io_->run();
    throw DeviceFault(FaultKind::Timeout, fmt::format("{}: the name did not resolve within 5 s", link->name_));
  }
  link->io_->restart();
  if (*resolved || found.empty()) {
    throw DeviceFault(FaultKind::Disconnected,
                      fmt::format("{}: cannot resolve it: {}", link->name_,
                                  *resolved ? resolved->message() : std::string("no IPv4 address")));
  }
  link->peer_ = found.begin()->endpoint();
  link->socket_ = std::make_unique<udp::socket>(*link->io_);
  link->socket_->open(udp::v4(), error);
  if (!error) link->socket_->bind(udp::endpoint(udp::v4(), localPort), error);
  if (error) {
    const bool taken = error == asio::error::address_in_use;
    throw DeviceFault(
        taken ? FaultKind::Refused : FaultKind::Disconnected,
        fmt::format("{}: cannot listen on UDP port {} for its replies: {}{}", link->name_, localPort, error.message(),
                    taken ? " (is LightBurn, RDWorks or another rotafab talking to a controller?)" : ""));
  }
  return link;
}

DatagramLink::~DatagramLink() {
  boost::system::error_code ignored;
  if (socket_) socket_->close(ignored);
}

uint16_t DatagramLink::localPort() const {
  boost::system::error_code ignored;
  return socket_->local_endpoint(ignored).port();
}

void DatagramLink::drain() {
  boost::system::error_code error;
  std::vector<uint8_t> buffer(65536);
  while (socket_->available(error) > 0 && !error) {
    udp::endpoint from;
    socket_->receive_from(asio::buffer(buffer), from, 0, error);
  }
}

void DatagramLink::send(const std::vector<uint8_t>& datagram) {
  boost::system::error_code error;
  socket_->send_to(asio::buffer(datagram), peer_, 0, error);
  // A UDP send fails at once or not at all: no route, no interface.
  if (error) throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: cannot send: {}", name_, error.message()));
}

std::optional<std::vector<uint8_t>> DatagramLink::receive(Millis timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<Millis>(deadline - std::chrono::steady_clock::now());
    // At the deadline, a datagram already here still counts (this thread may have been kept waiting).
    boost::system::error_code ignored;
    if (left.count() <= 0 && socket_->available(ignored) == 0) return std::nullopt;
    std::vector<uint8_t> buffer(65536);
    udp::endpoint from;
    std::optional<boost::system::error_code> result;
    size_t got = 0;
    socket_->async_receive_from(asio::buffer(buffer), from,
                                [&](const boost::system::error_code& e, size_t n) { result = e, got = n; });
    io_->restart();
    io_->run_for(std::max(left, Millis(1)));
    if (!result) {
      boost::system::error_code ignored;
      socket_->cancel(ignored);
      io_->restart();
      io_->run();  // the cancelled handler
      if (!result || *result) return std::nullopt;
    }
    // An ICMP "port unreachable" for an earlier datagram: nobody listens
    // there (yet); as silence, the caller's retries decide.
    if (*result == asio::error::connection_refused) continue;
    if (*result) throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: {}", name_, result->message()));
    // From the controller's address, whatever its port: not every model answers from the one it listens on.
    if (from.address() != peer_.address()) continue;
    buffer.resize(got);
    return buffer;
  }
}

}  // namespace rotafab::devices
