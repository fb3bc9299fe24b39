#include "devices/DeviceUri.h"

#include <fmt/format.h>

#include <charconv>
#include <stdexcept>

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

// "1a86" as a USB vendor or product id.
std::optional<uint16_t> hexId(const std::string& text) {
  unsigned value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value, 16);
  if (text.size() != 4 || error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return static_cast<uint16_t>(value);
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
    std::string rest = uri.substr(4);
    const auto query = rest.find('?');
    if (query != std::string::npos) {
      const std::string option = rest.substr(query + 1);
      rest.erase(query);
      const std::string value = option.starts_with("speed=") ? option.substr(6) : "";
      const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), parsed.simulatedSpeed);
      if (value.empty() || error != std::errc() || end != value.data() + value.size() || !(parsed.simulatedSpeed > 0)) {
        throw bad(fmt::format("\"{}\": the simulator takes speed=N, a positive number", option));
      }
    }
    if (rest != "grbl" && rest != "m2nano") throw bad("the simulators are sim:grbl and sim:m2nano");
    parsed.driver = rest, parsed.transport = "sim";
    return parsed;
  }
  if (uri.starts_with("spool:")) {
    parsed.driver = "spool", parsed.transport = "folder", parsed.path = uri.substr(6);
    const auto query = parsed.path.find('?');
    if (query != std::string::npos) {
      const std::string option = parsed.path.substr(query + 1);
      parsed.path.erase(query);
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
    std::string rest = uri.substr(7);
    const auto query = rest.find('?');
    if (query != std::string::npos) {
      const std::string options = rest.substr(query + 1);
      rest.erase(query);
      if (!options.starts_with("baud=")) throw bad(fmt::format("unknown option \"{}\" (only baud=N)", options));
      const std::string baud = options.substr(5);
      const auto [end, error] = std::from_chars(baud.data(), baud.data() + baud.size(), parsed.baud);
      if (error != std::errc() || end != baud.data() + baud.size() || parsed.baud == 0) {
        throw bad(fmt::format("baud={}: not a baud rate", baud));
      }
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
    std::string rest = uri.substr(9);
    const auto query = rest.find('?');
    std::string options = query == std::string::npos ? "" : rest.substr(query + 1);
    if (query != std::string::npos) rest.erase(query);
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
      int number = 0;
      const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
      if ((key != "bus" && key != "address") || value.empty() || error != std::errc() ||
          end != value.data() + value.size() || number <= 0) {
        throw bad(
            fmt::format("\"{}\": the M2 Nano takes bus=N and address=N (as `rotafab devices` shows them)", option));
      }
      (key == "bus" ? parsed.usbBus : parsed.usbAddress) = number;
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
