// rotafab-sim-m2nano [--speed N]: the simulated M2 Nano of sim:m2nano
// (SimEntries.h) and the real M2 Nano driver, in a program of their own:
// umockdev plugs the simulated board into libusb by a preloaded library, so
// the driver's libusb calls run as with a K40, and only this program needs
// it. It serves the driver over its standard input and output
// (devices/remote/DeviceHost.h) until its input ends.

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "devices/m2nano/M2NanoDriver.h"
#include "devices/remote/DeviceHost.h"
#include "devices/sim/M2NanoSimulator.h"

namespace {

using namespace rotafab::devices;

// An M2 Nano driver that owns the simulated board it talks to.
class SimulatedM2Nano : public m2nano::M2NanoDriver {
 public:
  explicit SimulatedM2Nano(std::unique_ptr<sim::M2NanoSimulator> simulator)
      : M2NanoDriver([match = simulator->match()] { return UsbLink::open(match, 0); }),
        simulator_(std::move(simulator)) {}
  ~SimulatedM2Nano() override { disconnect(); }  // libusb lets go of the device before it goes

 private:
  std::unique_ptr<sim::M2NanoSimulator> simulator_;
};

}  // namespace

int main(int argc, char** argv) {
  // The program that started this one decides when a job stops (it sends a
  // cancel, or goes, and the input ends): Ctrl-C at the terminal, the
  // terminal closing, reach it, not this; nor does a write to a closed pipe
  // end this mid-job.
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  double speed = 1;
  if (argc == 3 && std::string(argv[1]) == "--speed") speed = std::atof(argv[2]);
  if (argc != 1 && argc != 3) {
    std::fprintf(stderr, "usage: %s [--speed N]\n(started by rotafab for --device sim:m2nano)\n", argv[0]);
    return 2;
  }
  std::unique_ptr<Device> device;
  try {
    sim::runUnderUmockdev(argv);
    sim::M2NanoSimulatorOptions options;
    options.timeScale = speed > 0 ? speed : 1;
    device = std::make_unique<SimulatedM2Nano>(std::make_unique<sim::M2NanoSimulator>(options));
  } catch (const std::exception& error) {
    remote::serveError(std::string("sim:m2nano: ") + error.what(), 0, 1);
    return 1;
  }
  remote::serveDevice(*device, 0, 1);
  return 0;
}
