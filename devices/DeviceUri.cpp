#include "devices/DeviceUri.h"

#include <fmt/format.h>

#include <charconv>
#include <stdexcept>
#include <tuple>
#include <type_traits>
#include <utility>

#include "devices/grbl/GrblDriver.h"
#include "devices/m2nano/M2NanoDriver.h"
#include "devices/sim/GrblSimulator.h"
#include "devices/sim/M2NanoSimulator.h"
#include "devices/spool/SpoolDevice.h"

namespace rotafab::devices {
namespace {

// A GRBL driver that owns the simulator it talks to.
class SimulatedGrbl : public grbl::GrblDriver {
 public:
  explicit SimulatedGrbl(std::unique_ptr<sim::GrblSimulator> simulator)
      : GrblDriver([path = simulator->path()] { return openSerialLink(path, 115200); }),
        simulator_(std::move(simulator)) {}

 private:
  std::unique_ptr<sim::GrblSimulator> simulator_;
};

// An M2 Nano driver that owns the simulated board it talks to (over libusb, through umockdev).
class SimulatedM2Nano : public m2nano::M2NanoDriver {
 public:
  explicit SimulatedM2Nano(std::unique_ptr<sim::M2NanoSimulator> simulator)
      : M2NanoDriver([match = simulator->match()] { return UsbLink::open(match, 0); }),
        simulator_(std::move(simulator)) {}
  ~SimulatedM2Nano() override { disconnect(); }  // libusb lets go of the device before it goes

 private:
  std::unique_ptr<sim::M2NanoSimulator> simulator_;
};

// `text` as a number, all of it (nothing when anything else is there).
template <typename Number>
std::optional<Number> wholeNumber(const std::string& text, int base = 10) {
  Number value{};
  const char* last = text.data() + text.size();
  std::from_chars_result result;
  if constexpr (std::is_floating_point_v<Number>) {
    result = std::from_chars(text.data(), last, value);
  } else {
    result = std::from_chars(text.data(), last, value, base);
  }
  if (text.empty() || result.ec != std::errc() || result.ptr != last) return std::nullopt;
  return value;
}

// "1a86" as a USB vendor or product id.
std::optional<uint16_t> hexId(const std::string& text) {
  const auto value = wholeNumber<unsigned>(text, 16);
  if (text.size() != 4 || !value) return std::nullopt;
  return static_cast<uint16_t>(*value);
}

// "path?query" as the path and the query (empty when there is none).
std::pair<std::string, std::string> splitQuery(const std::string& rest) {
  const auto query = rest.find('?');
  if (query == std::string::npos) return {rest, ""};
  return {rest.substr(0, query), rest.substr(query + 1)};
}

}  // namespace

DeviceUri parseDeviceUri(const std::string& uri) {
  const auto bad = [&](const std::string& what) {
    return std::invalid_argument(
        fmt::format("--device {}: {} (e.g. grbl:///dev/ttyUSB0?baud=115200, "
                    "grbl+tcp://192.168.4.1:23, sim:grbl)",
                    uri, what));
  };
  DeviceUri parsed;
  if (uri.starts_with("sim:")) {
    const auto [rest, option] = splitQuery(uri.substr(4));
    if (uri.find('?') != std::string::npos) {
      const auto speed = wholeNumber<double>(option.starts_with("speed=") ? option.substr(6) : "");
      if (!speed || !(*speed > 0)) {
        throw bad(fmt::format("\"{}\": the simulator takes speed=N, a positive number", option));
      }
      parsed.simulatedSpeed = *speed;
    }
    if (rest != "grbl" && rest != "m2nano") throw bad("the simulators are sim:grbl and sim:m2nano");
    parsed.driver = rest, parsed.transport = "sim";
    return parsed;
  }
  if (uri.starts_with("spool:")) {
    parsed.driver = "spool", parsed.transport = "folder";
    std::string option;
    std::tie(parsed.path, option) = splitQuery(uri.substr(6));
    if (uri.find('?') != std::string::npos) {
      if (!option.starts_with("printer=") || option.size() == 8) {
        throw bad(fmt::format("\"{}\": the spool takes printer=NAME", option));
      }
      parsed.printer = option.substr(8);
    }
    if (parsed.path.empty()) throw bad("no folder after spool:");
    return parsed;
  }
  if (uri.starts_with("grbl://")) {
    parsed.driver = "grbl", parsed.transport = "serial";
    const auto [rest, options] = splitQuery(uri.substr(7));
    if (uri.find('?') != std::string::npos) {
      if (!options.starts_with("baud=")) throw bad(fmt::format("unknown option \"{}\" (only baud=N)", options));
      const std::string baud = options.substr(5);
      const auto value = wholeNumber<unsigned>(baud);
      if (!value || *value == 0) throw bad(fmt::format("baud={}: not a baud rate", baud));
      parsed.baud = *value;
    }
    if (!rest.starts_with("/")) throw bad("the serial port must be an absolute path, as in grbl:///dev/ttyUSB0");
    parsed.path = rest;
    return parsed;
  }
  if (uri.starts_with("grbl+tcp://")) {
    parsed.driver = "grbl", parsed.transport = "tcp";
    const std::string rest = uri.substr(11);
    const auto colon = rest.rfind(':');
    parsed.path = rest.substr(0, colon);
    parsed.port = colon == std::string::npos ? "23" : rest.substr(colon + 1);
    if (parsed.path.empty()) throw bad("no host");
    return parsed;
  }
  if (uri.starts_with("m2nano://")) {
    // m2nano://usb/1a86:5512[?bus=B&address=A]
    parsed.driver = "m2nano", parsed.transport = "usb";
    auto [rest, options] = splitQuery(uri.substr(9));
    const auto colon = rest.find(':');
    const bool usb = rest.starts_with("usb/") && colon != std::string::npos && colon > 4;
    const auto vendor = usb ? hexId(rest.substr(4, colon - 4)) : std::nullopt;
    const auto product = usb ? hexId(rest.substr(colon + 1)) : std::nullopt;
    if (!vendor || !product) {
      throw bad("the M2 Nano is m2nano://usb/VENDOR:PRODUCT in hex, e.g. m2nano://usb/1a86:5512");
    }
    parsed.usbVendor = *vendor, parsed.usbProduct = *product;
    while (!options.empty()) {
      const auto amp = options.find('&');
      const std::string option = options.substr(0, amp);
      options = amp == std::string::npos ? "" : options.substr(amp + 1);
      const auto equals = option.find('=');
      const std::string key = option.substr(0, equals),
                        value = equals == std::string::npos ? "" : option.substr(equals + 1);
      const auto number = wholeNumber<int>(value);
      if ((key != "bus" && key != "address") || !number || *number <= 0) {
        throw bad(
            fmt::format("\"{}\": the M2 Nano takes bus=N and address=N (as `rotafab devices` shows them)", option));
      }
      (key == "bus" ? parsed.usbBus : parsed.usbAddress) = *number;
    }
    return parsed;
  }
  throw bad("not a device URI this program knows");
}

std::unique_ptr<Device> openDevice(const DeviceUri& uri, const std::map<jobs::Operation, jobs::Rgb>& colours) {
  if (uri.driver == "spool") return std::make_unique<spool::SpoolDevice>(uri.path, uri.printer, colours);
  if (uri.driver == "grbl" && uri.transport == "sim") {
    sim::GrblSimulatorOptions options;
    options.timeScale = uri.simulatedSpeed;
    return std::make_unique<SimulatedGrbl>(std::make_unique<sim::GrblSimulator>(options));
  }
  if (uri.driver == "grbl" && uri.transport == "serial") {
    return std::make_unique<grbl::GrblDriver>([uri] { return openSerialLink(uri.path, uri.baud); });
  }
  if (uri.driver == "grbl" && uri.transport == "tcp") {
    return std::make_unique<grbl::GrblDriver>([uri] { return openTcpLink(uri.path, uri.port, Millis(5000)); });
  }
  if (uri.driver == "m2nano" && uri.transport == "sim") {
    sim::M2NanoSimulatorOptions options;
    options.timeScale = uri.simulatedSpeed;
    return std::make_unique<SimulatedM2Nano>(std::make_unique<sim::M2NanoSimulator>(options));
  }
  if (uri.driver == "m2nano" && uri.transport == "usb") {
    const UsbMatch match{uri.usbVendor, uri.usbProduct, uri.usbBus, uri.usbAddress};
    return std::make_unique<m2nano::M2NanoDriver>([match] { return UsbLink::open(match, 0); });
  }
  throw std::invalid_argument(fmt::format("no {} driver over {}", uri.driver, uri.transport));
}

}  // namespace rotafab::devices
