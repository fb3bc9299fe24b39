#pragma once
// A byte stream to a controller, serial (a tty or a pseudo-terminal) or TCP,
// on Boost.Asio, with a timeout on every read and write. A timeout throws
// DeviceFault Timeout; the port closing, the device unplugged or the
// connection dropped throws DeviceFault Disconnected. One thread uses a link:
// a driver takes requests from other threads (hold, resume, cancel) between
// its reads, which are short.

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it (C++20)

#include <boost/asio.hpp>
#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "devices/Device.h"

namespace rotafab::devices {

using Millis = std::chrono::milliseconds;

class Link {
 public:
  virtual ~Link() = default;
  virtual void write(const std::string& bytes, Millis timeout) = 0;
  // One line without its line ending ("\r\n" or "\n"); nothing when `timeout` passes first.
  virtual std::optional<std::string> readLine(Millis timeout) = 0;
  // The bytes that have come, as they came (a binary protocol's); nothing
  // when `timeout` passes first.
  virtual std::optional<std::string> readSome(Millis timeout) = 0;
  virtual void close() = 0;
  [[nodiscard]] virtual std::string name() const = 0;
};

// `path`: /dev/ttyUSB0, /dev/pts/3, ...
std::unique_ptr<Link> openSerialLink(const std::string& path, unsigned baud);
// GRBL over telnet (ESP32 boards, ser2net): host and port.
std::unique_ptr<Link> openTcpLink(const std::string& host, const std::string& port, Millis timeout);

}  // namespace rotafab::devices
