#include "devices/sim/SimEntries.h"

#include <fmt/format.h>

#include <cstdio>

#include "core/ProgramFolders.h"
#include "devices/UriParts.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/m2nano/Lhymicro.h"
#include "devices/remote/RemoteDevice.h"
#include "devices/sim/GrblSimulator.h"

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

// The faults a simulated GRBL can be told to have, for a drill of what the
// operator sees (and for the command line's tests).
constexpr const char* kGrblFaults = "stall, noise, garbage, alarm, silence or unplug";

// sim:NAME[?speed=N][&fault=KIND[&after=LINES]][&witness=FILE][&cuts=FILE][&latency=MS]
std::unique_ptr<SimAddress> parseSim(const std::string& uri, bool faults) {
  auto parsed = std::make_unique<SimAddress>(uri);
  std::string query = splitQuery(uri).second;
  const std::string takes =
      faults ? fmt::format("speed=N, fault=KIND ({}), after=LINES, witness=FILE, cuts=FILE and latency=MS", kGrblFaults)
             : "speed=N, a positive number";
  while (!query.empty()) {
    const size_t end = query.find('&');
    const std::string option = query.substr(0, end);
    query = end == std::string::npos ? "" : query.substr(end + 1);
    const size_t equals = option.find('=');
    const std::string key = option.substr(0, equals),
                      value = equals == std::string::npos ? "" : option.substr(equals + 1);
    if (key == "speed") {
      const auto speed = wholeNumber<double>(value);
      if (!speed || !(*speed > 0)) throw uriError(uri, fmt::format("\"{}\": the simulator takes {}", option, takes));
      parsed->speed = *speed;
    } else if (faults && key == "fault" &&
               (value == "stall" || value == "noise" || value == "garbage" || value == "alarm" || value == "silence" ||
                value == "unplug")) {
      parsed->fault = value;
    } else if (faults && key == "after" && wholeNumber<size_t>(value)) {
      parsed->after = *wholeNumber<size_t>(value);
    } else if (faults && key == "witness" && !value.empty()) {
      parsed->witness = value;
    } else if (faults && key == "cuts" && !value.empty()) {
      parsed->cutWitness = value;
    } else if (faults && key == "latency" && wholeNumber<unsigned>(value) && *wholeNumber<unsigned>(value) <= 10000) {
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
    return parseSim(uri, true);
  }
  [[nodiscard]] std::unique_ptr<Device> open(const DeviceAddress& address, const DeviceSetup&) const override {
    const auto& sim = dynamic_cast<const SimAddress&>(address);
    GrblSimulatorOptions options;
    options.timeScale = sim.speed;
    options.replyLatency = std::chrono::milliseconds(sim.latencyMs);
    if (!sim.witness.empty()) {
      options.laserChanged = [file = sim.witness](bool lit) {
        // Appended and closed at once: what is written survives a kill of the process.
        if (FILE* out = std::fopen(file.c_str(), "a")) {
          std::fputs(lit ? "on\n" : "off\n", out);
          std::fclose(out);
        }
      };
    }
    if (!sim.cutWitness.empty()) {
      options.litMoveFinished = [file = sim.cutWitness](const std::array<double, 4>& move) {
        // A line for each lit move finished: what was cut, as it was cut.
        if (FILE* out = std::fopen(file.c_str(), "a")) {
          std::fputs(fmt::format("{:.3f} {:.3f} {:.3f} {:.3f}\n", move[0], move[1], move[2], move[3]).c_str(), out);
          std::fclose(out);
        }
      };
    }
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
    return parseSim(uri, false);
  }
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
