#include "devices/transport/DatagramLink.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace rotafab::devices {
namespace {

namespace asio = boost::asio;
using asio::ip::udp;

// The IPv4 address of `host`: an address as it is, a name looked up within
// 5 s. (getaddrinfo cannot be interrupted: a lookup that takes longer, with
// a dead DNS server, is left to end on a thread of its own.)
asio::ip::address_v4 lookUp(const std::string& host, const std::string& name) {
  boost::system::error_code error;
  const auto address = asio::ip::make_address_v4(host, error);
  if (!error) return address;
  struct Lookup {
    std::mutex mutex;
    std::condition_variable done;
    bool finished = false;
    std::optional<asio::ip::address_v4> address;
    std::string error;
  };
  auto lookup = std::make_shared<Lookup>();
  std::thread([lookup, host] {
    asio::io_context io;
    udp::resolver resolver(io);
    boost::system::error_code failed;
    const auto found = resolver.resolve(udp::v4(), host, "", failed);
    std::lock_guard lock(lookup->mutex);
    if (!failed && !found.empty()) lookup->address = found.begin()->endpoint().address().to_v4();
    lookup->error = failed ? failed.message() : std::string("no IPv4 address");
    lookup->finished = true;
    lookup->done.notify_all();
  }).detach();
  std::unique_lock lock(lookup->mutex);
  if (!lookup->done.wait_for(lock, std::chrono::seconds(5), [&] { return lookup->finished; })) {
    throw DeviceFault(FaultKind::Timeout, fmt::format("{}: the name did not resolve within 5 s", name));
  }
  if (!lookup->address)
    throw DeviceFault(FaultKind::Disconnected, fmt::format("{}: cannot resolve it: {}", name, lookup->error));
  return *lookup->address;
}

}  // namespace

std::unique_ptr<DatagramLink> DatagramLink::open(const std::string& host, uint16_t port, uint16_t localPort) {
  std::unique_ptr<DatagramLink> link(new DatagramLink);
  link->name_ = fmt::format("{}:{}", host, port);
  link->io_ = std::make_unique<asio::io_context>();
  boost::system::error_code error;
  link->peer_ = udp::endpoint(lookUp(host, link->name_), port);
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
  for (int dropped = 0; dropped < 64 && socket_->available(error) > 0 && !error; ++dropped) {
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
