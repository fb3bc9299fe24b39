#include "devices/DeviceUri.h"

#include <fmt/format.h>

#include <charconv>
#include <stdexcept>

#include "devices/grbl/GrblDriver.h"
#include "devices/sim/GrblSimulator.h"
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
    parsed.driver = "m2nano", parsed.transport = "usb", parsed.path = uri.substr(9);
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
  throw std::invalid_argument(
      fmt::format("the {} driver is not built yet (issue 5: the M2 Nano over USB is still to come)", uri.driver));
}

}  // namespace rotafab::devices
