// The M2 Nano driver's entry in the registry (DriverEntry.h).

#include <fmt/format.h>

#include "devices/UriParts.h"
#include "devices/m2nano/M2NanoDriver.h"

namespace rotafab::devices::m2nano {
namespace {

constexpr uint16_t kCh341Vendor = 0x1a86, kCh341Parallel = 0x5512;

struct M2NanoAddress : DeviceAddress {
  using DeviceAddress::DeviceAddress;
  UsbMatch match{kCh341Vendor, kCh341Parallel, std::nullopt, std::nullopt};
};

class M2NanoEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "m2nano"; }
  [[nodiscard]] std::string_view scheme() const override { return "m2nano://"; }
  [[nodiscard]] bool takes(std::string_view uri) const override { return uri.starts_with("m2nano://"); }
  [[nodiscard]] std::vector<UsbId> usbIds() const override { return {{kCh341Vendor, kCh341Parallel}}; }
  [[nodiscard]] std::string uriForUsbDevice(int, int) const override { return "m2nano://usb/1a86:5512"; }
  [[nodiscard]] std::string usbDescription() const override { return "CH341 in parallel mode (Lihuiyu M2 Nano, K40)"; }

  // m2nano://usb/1a86:5512[?bus=B&address=A]
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    auto parsed = std::make_unique<M2NanoAddress>(uri);
    auto [rest, options] = splitQuery(uri.substr(9));
    const auto colon = rest.find(':');
    const bool usb = rest.starts_with("usb/") && colon != std::string::npos && colon > 4;
    const auto vendor = usb ? hexId(rest.substr(4, colon - 4)) : std::nullopt;
    const auto product = usb ? hexId(rest.substr(colon + 1)) : std::nullopt;
    if (!vendor || !product) {
      throw uriError(uri, "the M2 Nano is m2nano://usb/VENDOR:PRODUCT in hex, e.g. m2nano://usb/1a86:5512");
    }
    parsed->match.vendor = *vendor, parsed->match.product = *product;
    for (const auto& [option, key, value] : queryOptions(options)) {
      const auto number = wholeNumber<int>(value);
      if ((key != "bus" && key != "address") || !number || *number <= 0) {
        throw uriError(
            uri,
            fmt::format("\"{}\": the M2 Nano takes bus=N and address=N (as `rotafab devices` shows them)", option));
      }
      (key == "bus" ? parsed->match.bus : parsed->match.address) = *number;
    }
    return parsed;
  }

  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    const UsbMatch match = dynamic_cast<const M2NanoAddress&>(address).match;
    return std::make_unique<M2NanoDriver>([match] { return UsbLink::open(match, 0); });
  }
};

}  // namespace

const DriverEntry& entry() {
  static const M2NanoEntry m2nano;
  return m2nano;
}

}  // namespace rotafab::devices::m2nano
