#pragma once
// UDP to one peer (a Ruida controller on the network), on Boost.Asio, with
// a timeout on every receive: each datagram is one message. The local port
// is the one the peer answers to (a Ruida controller sends its replies to
// port 40200, whatever port they came from); 0 binds any free port, for a
// peer that answers the sender (a simulator). Datagrams from any other
// address are dropped. One thread uses a link.

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it (C++20)

#include <boost/asio.hpp>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "devices/transport/SerialLink.h"

namespace rotafab::devices {

class DatagramLink {
 public:
  // Resolves `host` (an IPv4 address or a name) and binds `localPort` on
  // every interface. Throws DeviceFault: Disconnected when the host cannot
  // be resolved, Refused when the local port is taken (with what to do).
  static std::unique_ptr<DatagramLink> open(const std::string& host, uint16_t port, uint16_t localPort);
  ~DatagramLink();
  DatagramLink(const DatagramLink&) = delete;
  DatagramLink& operator=(const DatagramLink&) = delete;

  void send(const std::vector<uint8_t>& datagram);
  // Drops the datagrams that have come and not been read (late answers to earlier ones).
  void drain();
  // The next datagram from the peer, or nothing once `timeout` has passed.
  std::optional<std::vector<uint8_t>> receive(Millis timeout);
  // "192.168.1.100:50200"
  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] uint16_t localPort() const;

 private:
  DatagramLink() = default;
  std::string name_;
  std::unique_ptr<boost::asio::io_context> io_;
  std::unique_ptr<boost::asio::ip::udp::socket> socket_;
  boost::asio::ip::udp::endpoint peer_;
};

}  // namespace rotafab::devices
