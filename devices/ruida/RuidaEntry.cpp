// The Ruida driver's entries in the registry (DriverEntry.h).

#include <fmt/format.h>

#include <algorithm>

#include "devices/UriParts.h"
#include "devices/ruida/RuidaDiscovery.h"
#include "devices/ruida/RuidaDriver.h"

namespace rotafab::devices::ruida {
namespace {

constexpr uint16_t kControllerPort = 50200;  // where a controller listens
constexpr uint16_t kReplyPort = 40200;       // where it sends its answers

struct RuidaAddress : DeviceAddress {
  using DeviceAddress::DeviceAddress;
  bool serial = false;
  std::string host;  // or the serial port
  uint16_t port = kControllerPort, bind = kReplyPort;
  unsigned baud = 115200;
  uint8_t magic = kDefaultMagic;
};

std::invalid_argument ruidaUriError(const std::string& uri, const std::string& what) {
  return std::invalid_argument(
      uri + ": " + what + " (e.g. ruida://192.168.1.100, ruida://laser.local?magic=0x11, ruida+serial:///dev/ttyUSB0)");
}

// The options after '?': those both URIs take (magic) and the kind's own.
void readOptions(const std::string& uri, const std::string& query, RuidaAddress& address) {
  const std::string takes = address.serial ? "baud=N and magic=0xNN" : "bind=PORT (0: any free port) and magic=0xNN";
  for (const auto& [option, key, value] : queryOptions(query)) {
    if (key == "magic" && value.starts_with("0x") && wholeNumber<unsigned>(value.substr(2), 16) &&
        *wholeNumber<unsigned>(value.substr(2), 16) <= 0xFF) {
      address.magic = static_cast<uint8_t>(*wholeNumber<unsigned>(value.substr(2), 16));
    } else if (!address.serial && key == "bind" && wholeNumber<unsigned>(value) &&
               *wholeNumber<unsigned>(value) <= 65535) {
      address.bind = static_cast<uint16_t>(*wholeNumber<unsigned>(value));
    } else if (address.serial && key == "baud" && wholeNumber<unsigned>(value) && *wholeNumber<unsigned>(value) > 0) {
      address.baud = *wholeNumber<unsigned>(value);
    } else {
      throw ruidaUriError(uri, fmt::format("\"{}\": a Ruida URI takes {}", option, takes));
    }
  }
}

class RuidaEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "ruida"; }
  [[nodiscard]] std::string_view scheme() const override { return "ruida://"; }
  [[nodiscard]] bool takes(std::string_view uri) const override {
    return uri.starts_with("ruida://") || uri.starts_with("ruida+serial://");
  }

  // A Ruida's USB port is an FTDI FT232 serial adapter (as many GRBL boards' are).
  [[nodiscard]] std::vector<UsbId> usbIds() const override { return {{0x0403, 0x6001}}; }
  [[nodiscard]] std::string uriForSerialPort(const std::string& port) const override {
    return "ruida+serial://" + port;
  }
  // Every controller on the local network that answers a read of its card ID.
  [[nodiscard]] std::vector<NetworkDevice> findOnNetwork() const override {
    std::vector<NetworkDevice> found;
    for (const FoundController& c : probeControllers("255.255.255.255", kControllerPort, kReplyPort, Millis(500))) {
      found.push_back({"ruida://" + c.address, fmt::format("Ruida controller, card 0x{:08X}", c.card)});
    }
    return found;
  }

  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    auto parsed = std::make_unique<RuidaAddress>(uri);
    parsed->serial = uri.starts_with("ruida+serial://");
    const auto [rest, query] = splitQuery(uri.substr(parsed->serial ? 15 : 8));
    readOptions(uri, query, *parsed);
    if (parsed->serial) {
      if (!rest.starts_with("/")) throw ruidaUriError(uri, "the USB port must be an absolute path");
      parsed->host = rest;
      return parsed;
    }
    std::string where = rest;
    if (where.ends_with("/")) where.pop_back();
    if (where.find('[') != std::string::npos || std::count(where.begin(), where.end(), ':') > 1) {
      throw ruidaUriError(uri, "Ruida controllers speak IPv4 only: give its IPv4 address or name");
    }
    const auto colon = where.rfind(':');
    parsed->host = where.substr(0, colon);
    if (parsed->host.empty() || parsed->host.find('/') != std::string::npos) {
      throw ruidaUriError(uri, "no host: the controller's IP address or name");
    }
    if (colon != std::string::npos) {
      const auto port = wholeNumber<unsigned>(where.substr(colon + 1));
      if (!port || *port == 0 || *port > 65535) throw ruidaUriError(uri, "not a UDP port after the host");
      parsed->port = static_cast<uint16_t>(*port);
    }
    return parsed;
  }

  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup& setup) const override {
    const auto& at = dynamic_cast<const RuidaAddress&>(address);
    if (at.serial) {
      return std::make_unique<RuidaDriver>([at] { return serialChannel(openSerialLink(at.host, at.baud), at.magic); },
                                           at.magic, setup.motion);
    }
    return std::make_unique<RuidaDriver>(
        [at] { return udpChannel(DatagramLink::open(at.host, at.port, at.bind), at.magic); }, at.magic, setup.motion);
  }

  [[nodiscard]] std::string dryRunNote(const DeviceAddress& address) const override {
    return fmt::format(
        "dry run: the job as RDWorks saves it (.rd, magic 0x{:02X}), for a USB stick or the "
        "controller's own file menu",
        dynamic_cast<const RuidaAddress&>(address).magic);
  }
};

}  // namespace

const DriverEntry& entry() {
  static const RuidaEntry ruida;
  return ruida;
}

}  // namespace rotafab::devices::ruida
