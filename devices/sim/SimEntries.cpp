#include "devices/sim/SimEntries.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

#include <cstdio>

#include "core/ProgramFolders.h"
#include "devices/UriParts.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/m2nano/Lhymicro.h"
#include "devices/remote/RemoteDevice.h"
#include "devices/ruida/RuidaDriver.h"
#include "devices/sim/GrblSimulator.h"
#include "devices/sim/RuidaSimulator.h"

namespace rotafab::devices::sim {
namespace {

constexpr double kDefaultSimSpeed = 50;

struct SimAddress : DeviceAddress {
  using DeviceAddress::DeviceAddress;
  // Simulated seconds per real second: by default fast, as a new user
  // expects of a simulator (a sheet of 10 minutes in 12 s); ?speed=1 for
  // real time. The times said are still the real machine's.
  double speed = kDefaultSimSpeed;
  // A fault to rehearse (sim:grbl only), once `after` lines have run.
  std::string fault;
  size_t after = 20;
  // A file the simulated laser's every change is appended to ("on", "off"),
  // for a test that watches the laser from outside the process.
  std::string witness, cutWitness;
  // Each reply this much later (a slow USB adapter's; a check that takes its time).
  int latencyMs = 0;
};

// The faults a simulator can be told to have, for a drill of what the
// operator sees (and for the command line's tests), and what `after` counts.
struct SimFaults {
  std::vector<std::string_view> kinds;
  std::string_view counted;
  bool latency = false;  // whether it can be told to answer late
};
const SimFaults kGrblFaults{{"stall", "noise", "garbage", "alarm", "silence", "unplug"}, "LINES", true};
const SimFaults kRuidaFaults{{"drop", "corrupt", "silence"}, "PACKETS", false};
const SimFaults kNoFaults{};

// sim:NAME[?speed=N][&fault=KIND[&after=COUNT]][&witness=FILE][&cuts=FILE][&latency=MS]
std::unique_ptr<SimAddress> parseSim(const std::string& uri, const SimFaults& simFaults) {
  auto parsed = std::make_unique<SimAddress>(uri);
  std::string query = splitQuery(uri).second;
  const bool faults = !simFaults.kinds.empty();
  std::string kinds;
  for (size_t k = 0; k < simFaults.kinds.size(); ++k) {
    kinds += fmt::format("{}{}", k == 0 ? "" : k + 1 == simFaults.kinds.size() ? " or " : ", ", simFaults.kinds[k]);
  }
  const std::string takes =
      faults ? fmt::format("speed=N, fault=KIND ({}), after={}, witness=FILE{}", kinds, simFaults.counted,
                           simFaults.latency ? ", cuts=FILE and latency=MS" : " and cuts=FILE")
             : "speed=N, a positive number";
  for (const auto& [option, key, value] : queryOptions(query)) {
    if (key == "speed") {
      const auto speed = wholeNumber<double>(value);
      if (!speed || !(*speed > 0)) throw uriError(uri, fmt::format("\"{}\": the simulator takes {}", option, takes));
      parsed->speed = *speed;
    } else if (faults && key == "fault" &&
               std::find(simFaults.kinds.begin(), simFaults.kinds.end(), value) != simFaults.kinds.end()) {
      parsed->fault = value;
    } else if (faults && key == "after" && wholeNumber<size_t>(value)) {
      parsed->after = *wholeNumber<size_t>(value);
    } else if (faults && key == "witness" && !value.empty()) {
      parsed->witness = value;
    } else if (faults && key == "cuts" && !value.empty()) {
      parsed->cutWitness = value;
    } else if (simFaults.latency && key == "latency" && wholeNumber<unsigned>(value) &&
               *wholeNumber<unsigned>(value) <= 10000) {
      parsed->latencyMs = static_cast<int>(*wholeNumber<unsigned>(value));
    } else {
      throw uriError(uri, fmt::format("\"{}\": the simulator takes {}", option, takes));
    }
  }
  return parsed;
}

// Injects the fault of `address` into `simulator`.
void rehearse(const SimAddress& address, GrblSimulator& simulator) {
  if (address.fault.empty()) return;
  simulator.afterLines(address.after, [fault = address.fault](GrblSimulator& s) {
    if (fault == "stall") s.stall();
    if (fault == "noise") s.garbleNextStatus(), s.sendGarbage();  // line noise once: the job goes on
    if (fault == "garbage")
      for (int i = 0; i < 3; ++i) s.sendGarbage();
    if (fault == "alarm") s.raiseAlarm(1);
    if (fault == "silence") s.mute(true);
    if (fault == "unplug") s.unplug();
  });
}

// Appended and closed at once: what is written survives a kill of the process.
void appendLine(const std::string& file, const std::string& line) {
  if (FILE* out = std::fopen(file.c_str(), "a")) {
    std::fputs(line.c_str(), out);
    std::fclose(out);
  }
}

// What writes the simulated laser's every change to `file` ("on", "off"); nothing for no file.
std::function<void(bool)> laserWitness(const std::string& file) {
  if (file.empty()) return {};
  return [file](bool lit) { appendLine(file, lit ? "on\n" : "off\n"); };
}

// What writes a line for each lit move finished to `file`: what was cut, as it was cut.
std::function<void(const std::array<double, 4>&)> cutWitness(const std::string& file) {
  if (file.empty()) return {};
  return [file](const std::array<double, 4>& move) {
    appendLine(file, fmt::format("{:.3f} {:.3f} {:.3f} {:.3f}\n", move[0], move[1], move[2], move[3]));
  };
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
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    return parseSim(uri, kGrblFaults);
  }
  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    const auto& sim = dynamic_cast<const SimAddress&>(address);
    GrblSimulatorOptions options;
    options.timeScale = sim.speed;
    options.replyLatency = std::chrono::milliseconds(sim.latencyMs);
    options.laserChanged = laserWitness(sim.witness);
    options.litMoveFinished = cutWitness(sim.cutWitness);
    auto simulator = std::make_unique<GrblSimulator>(options);
    rehearse(sim, *simulator);
    return std::make_unique<SimulatedGrbl>(std::move(simulator), options.timeScale);
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
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    return parseSim(uri, kNoFaults);
  }
  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    return std::make_unique<SimulatedM2Nano>(dynamic_cast<const SimAddress&>(address).speed);
  }
};

// A Ruida driver that owns the controller it talks to, on loopback UDP.
class SimulatedRuida : public ruida::RuidaDriver {
 public:
  SimulatedRuida(std::unique_ptr<RuidaSimulator> simulator, const jobs::MotionLimits& motion, double speed)
      : RuidaDriver(
            [port = simulator->port()] {
              return ruida::udpChannel(DatagramLink::open("127.0.0.1", port, 0), ruida::kDefaultMagic);
            },
            ruida::kDefaultMagic, motion, {}, speed),
        simulator_(std::move(simulator)) {}

 private:
  std::unique_ptr<RuidaSimulator> simulator_;
};

class SimRuidaEntry : public DriverEntry {
 public:
  [[nodiscard]] std::string_view name() const override { return "ruida"; }
  [[nodiscard]] std::string_view scheme() const override { return "sim:ruida"; }
  [[nodiscard]] bool simulated() const override { return true; }
  [[nodiscard]] bool takes(std::string_view uri) const override { return isSim(uri, "ruida"); }
  [[nodiscard]] std::unique_ptr<DeviceAddress> parse(const std::string& uri) const override {
    return parseSim(uri, kRuidaFaults);
  }
  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup& setup) const override {
    const auto& sim = dynamic_cast<const SimAddress&>(address);
    RuidaSimulatorOptions options;
    options.timeScale = sim.speed;
    if (setup.bedWidth > 0 && setup.bedHeight > 0) {  // the machine's bed, as its controller would report it
      options.bedWidth = setup.bedWidth * 25.4, options.bedHeight = setup.bedHeight * 25.4;
    }
    if (sim.fault == "drop") options.fault = RuidaFault::Drop;
    if (sim.fault == "corrupt") options.fault = RuidaFault::Corrupt;
    if (sim.fault == "silence") options.fault = RuidaFault::Silence;
    options.after = sim.after;
    options.laserChanged = laserWitness(sim.witness);
    options.cutFinished = cutWitness(sim.cutWitness);
    return std::make_unique<SimulatedRuida>(std::make_unique<RuidaSimulator>(options), setup.motion, sim.speed);
  }
};

}  // namespace

const DriverEntry& ruidaEntry() {
  static const SimRuidaEntry entry;
  return entry;
}

const DriverEntry& grblEntry() {
  static const SimGrblEntry entry;
  return entry;
}

const DriverEntry& m2nanoEntry() {
  static const SimM2NanoEntry entry;
  return entry;
}

}  // namespace rotafab::devices::sim
