// The spool's entry in the registry (DriverEntry.h).

#include <fmt/format.h>

#include "devices/UriParts.h"
#include "devices/spool/SpoolDevice.h"

namespace rotafab::devices::spool {
namespace {

struct SpoolAddress : DeviceAddress {
  using DeviceAddress::DeviceAddress;
  std::string folder, printer;  // no printer: the files only
};

class SpoolEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "spool"; }
  [[nodiscard]] std::string_view scheme() const override { return "spool:"; }
  [[nodiscard]] bool takes(std::string_view uri) const override { return uri.starts_with("spool:"); }
  [[nodiscard]] bool frames() const override { return false; }

  // spool:DIR[?printer=NAME]
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    auto parsed = std::make_unique<SpoolAddress>(uri);
    std::string option;
    std::tie(parsed->folder, option) = splitQuery(uri.substr(6));
    if (uri.find('?') != std::string::npos) {
      if (!option.starts_with("printer=") || option.size() == 8) {
        throw uriError(uri, fmt::format("\"{}\": the spool takes printer=NAME", option));
      }
      parsed->printer = option.substr(8);
    }
    if (parsed->folder.empty()) throw uriError(uri, "no folder after spool:");
    return parsed;
  }

  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup& setup) const override {
    const auto& at = dynamic_cast<const SpoolAddress&>(address);
    return std::make_unique<SpoolDevice>(at.folder, at.printer, setup.colours);
  }
};

}  // namespace

const DriverEntry& entry() {
  static const SpoolEntry spool;
  return spool;
}

}  // namespace rotafab::devices::spool
