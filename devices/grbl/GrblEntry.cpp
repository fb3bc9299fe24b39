// The GRBL driver's entry in the registry (DriverEntry.h).

#include <fmt/format.h>

#include "devices/UriParts.h"
#include "devices/grbl/GrblDriver.h"

namespace rotafab::devices::grbl {
namespace {

struct GrblAddress : DeviceAddress {
  using DeviceAddress::DeviceAddress;
  bool tcp = false;
  std::string path;  // the serial port, or the host
  std::string port;  // TCP
  unsigned baud = 115200;
};

class GrblEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "grbl"; }
  [[nodiscard]] std::string_view scheme() const override { return "grbl://"; }
  [[nodiscard]] bool takes(std::string_view uri) const override {
    return uri.starts_with("grbl://") || uri.starts_with("grbl+tcp://");
  }
  // CH340, FTDI FT232R, CP210x, and Arduino boards (any of their products).
  [[nodiscard]] std::vector<UsbId> usbIds() const override {
    return {{0x1a86, 0x7523}, {0x0403, 0x6001}, {0x10c4, 0xea60}, {0x2341, std::nullopt}, {0x2a03, std::nullopt}};
  }
  [[nodiscard]] std::string uriForSerialPort(const std::string& port) const override {
    return fmt::format("grbl://{}?baud=115200", port);
  }

  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    auto parsed = std::make_unique<GrblAddress>(uri);
    if (uri.starts_with("grbl+tcp://")) {
      parsed->tcp = true;
      const std::string rest = uri.substr(11);
      const auto colon = rest.rfind(':');
      parsed->path = rest.substr(0, colon);
      parsed->port = colon == std::string::npos ? "23" : rest.substr(colon + 1);
      if (parsed->path.empty()) throw uriError(uri, "no host");
      return parsed;
    }
    const auto [rest, options] = splitQuery(uri.substr(7));
    if (uri.find('?') != std::string::npos) {
      if (!options.starts_with("baud="))
        throw uriError(uri, fmt::format("unknown option \"{}\" (only baud=N)", options));
      const std::string baud = options.substr(5);
      const auto value = wholeNumber<unsigned>(baud);
      if (!value || *value == 0) throw uriError(uri, fmt::format("baud={}: not a baud rate", baud));
      parsed->baud = *value;
    }
    if (!rest.starts_with("/")) {
      throw uriError(uri, "the serial port must be an absolute path, as in grbl:///dev/ttyUSB0");
    }
    parsed->path = rest;
    return parsed;
  }

  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    const auto& at = dynamic_cast<const GrblAddress&>(address);
    if (at.tcp) {
      return std::make_unique<GrblDriver>([at] { return openTcpLink(at.path, at.port, Millis(5000)); });
    }
    return std::make_unique<GrblDriver>([at] { return openSerialLink(at.path, at.baud); });
  }

  // A dry run opens no real port: S and F follow GRBL's defaults.
  [[nodiscard]] std::string dryRunNote(const DeviceAddress&) const override {
    return "dry run: S and F for GRBL's default settings ($30=1000, $110=500 mm/min)";
  }
};

}  // namespace

const DriverEntry& entry() {
  static const GrblEntry grbl;
  return grbl;
}

}  // namespace rotafab::devices::grbl
