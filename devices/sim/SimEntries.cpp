#include "devices/sim/SimEntries.h"

#include <fmt/format.h>

#include "core/ProgramFolders.h"
#include "devices/UriParts.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/m2nano/Lhymicro.h"
#include "devices/remote/RemoteDevice.h"
#include "devices/sim/GrblSimulator.h"

namespace rotafab::devices::sim {
namespace {

struct SimAddress : DeviceAddress {
  using DeviceAddress::DeviceAddress;
  double speed = 1;  // simulated seconds per real second
};

// sim:NAME[?speed=N]
std::unique_ptr<SimAddress> parseSim(const std::string& uri) {
  auto parsed = std::make_unique<SimAddress>(uri);
  if (uri.find('?') != std::string::npos) {
    const std::string option = splitQuery(uri).second;
    const auto speed = wholeNumber<double>(option.starts_with("speed=") ? option.substr(6) : "");
    if (!speed || !(*speed > 0))
      throw uriError(uri, fmt::format("\"{}\": the simulator takes speed=N, a positive number", option));
    parsed->speed = *speed;
  }
  return parsed;
}

bool isSim(std::string_view uri, std::string_view name) {
  const std::string scheme = "sim:" + std::string(name);
  return uri == scheme || uri.starts_with(scheme + "?");
}

// A GRBL driver that owns the simulator it talks to.
class SimulatedGrbl : public grbl::GrblDriver {
 public:
  SimulatedGrbl(std::unique_ptr<GrblSimulator> simulator, double speed)
      : GrblDriver([path = simulator->path()] { return openSerialLink(path, 115200); }, {}, speed),
        simulator_(std::move(simulator)) {}

 private:
  std::unique_ptr<GrblSimulator> simulator_;
};

class SimGrblEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "grbl"; }
  [[nodiscard]] std::string_view scheme() const override { return "sim:grbl"; }
  [[nodiscard]] bool simulated() const override { return true; }
  [[nodiscard]] bool takes(std::string_view uri) const override { return isSim(uri, "grbl"); }
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override { return parseSim(uri); }
  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    GrblSimulatorOptions options;
    options.timeScale = dynamic_cast<const SimAddress&>(address).speed;
    return std::make_unique<SimulatedGrbl>(std::make_unique<GrblSimulator>(options), options.timeScale);
  }
  // The simulator is asked for its settings ($30, $110), as a real GRBL cannot be for a dry run.
  [[nodiscard]] bool connectsForDryRun(const DeviceAddress&) const override { return true; }
};

// The simulated M2 Nano and its driver, in the helper; its dry run is the M2 Nano's own, here.
class SimulatedM2Nano : public remote::RemoteDevice {
 public:
  explicit SimulatedM2Nano(double speed)
      : RemoteDevice({core::helperProgram(kM2NanoHelper), "--speed", fmt::format("{}", speed)}), speed_(speed) {}
  [[nodiscard]] double timeScale() const override { return speed_; }
  [[nodiscard]] jobs::MotionLimits motionLimits() const override { return m2nano::motionLimits(); }
  [[nodiscard]] std::string program(const std::vector<jobs::Toolpath>& toolpaths) const override {
    return m2nano::egvProgram(toolpaths);
  }
  [[nodiscard]] std::string describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const override {
    return m2nano::describeEgvProgram(toolpaths);
  }

 private:
  double speed_;
};

class SimM2NanoEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "m2nano"; }
  [[nodiscard]] std::string_view scheme() const override { return "sim:m2nano"; }
  [[nodiscard]] bool simulated() const override { return true; }
  [[nodiscard]] bool takes(std::string_view uri) const override { return isSim(uri, "m2nano"); }
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override { return parseSim(uri); }
  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    return std::make_unique<SimulatedM2Nano>(dynamic_cast<const SimAddress&>(address).speed);
  }
};

}  // namespace

const DriverEntry& grblEntry() {
  static const SimGrblEntry entry;
  return entry;
}

const DriverEntry& m2nanoEntry() {
  static const SimM2NanoEntry entry;
  return entry;
}

}  // namespace rotafab::devices::sim
