// Streaming G-code to the simulated GRBL over a pseudo-
// terminal paced at 115200 baud (10 bits a byte: 11 520 bytes/s), each
// reply reaching the driver `latency` after GRBL sends it (a USB serial
// adapter's round trip), with the simulated machine far faster than the
// line, so that only the streaming method limits the rate. Character
// counting keeps GRBL's 127-byte buffer full; send-and-wait leaves the line
// idle for every round trip. Reported: bytes acknowledged per second, to the
// last `ok`, and their share of the line's capacity.

#include <benchmark/benchmark.h>

#include <chrono>

#include "devices/grbl/GrblDriver.h"
#include "devices/ruida/RuidaDriver.h"
#include "devices/sim/GrblSimulator.h"
#include "devices/sim/RuidaSimulator.h"

namespace {

using namespace rotafab;

// Short strokes (as labels and holes are): many lines, each ~25 bytes.
jobs::Toolpath manyStrokes(int strokes) {
  jobs::Toolpath path;
  path.width = path.height = 15;
  for (int i = 0; i < strokes; ++i) {
    jobs::ToolpathStroke stroke;
    stroke.power = 0.5, stroke.speed = 1;
    const double x = 1 + (i % 40) * 0.3, y = 1 + (i / 40) * 0.3;
    stroke.points = {{x, y}, {x + 0.1, y}, {x + 0.1, y + 0.1}, {x, y + 0.1}, {x, y}};
    path.strokes.push_back(stroke);
  }
  return path;
}

void BM_GrblStreaming(benchmark::State& state) {
  const bool counting = state.range(0) != 0;
  const unsigned baud = 115200;
  const jobs::Toolpath path = manyStrokes(400);
  double bytes = 0, seconds = 0;
  for (auto _ : state) {
    devices::sim::GrblSimulatorOptions options;
    options.baud = baud;
    options.timeScale = 1e4;  // the machine is never the bottleneck
    options.replyLatency = std::chrono::milliseconds(state.range(1));
    devices::sim::GrblSimulator simulator(options);
    devices::grbl::GrblDriver driver([&] { return devices::openSerialLink(simulator.path(), baud); });
    driver.connect();
    driver.setCharacterCounting(counting);
    rotafab::core::Cancellation cancel;
    size_t acknowledged = 0;
    const auto started = std::chrono::steady_clock::now();
    auto lastAcknowledged = started;  // the rate counts to the last `ok`, not to the machine's stop
    const auto progress = [&](const devices::Progress& p) {
      acknowledged = p.bytesAcknowledged;
      lastAcknowledged = std::chrono::steady_clock::now();
    };
    driver.run(path, progress, cancel);
    const double elapsed = std::chrono::duration<double>(lastAcknowledged - started).count();
    state.SetIterationTime(elapsed);
    bytes += static_cast<double>(acknowledged), seconds += elapsed;
  }
  const double rate = bytes / seconds;
  state.counters["bytes/s"] = rate;
  state.counters["of_line"] = rate / (baud / 10.0);
}
BENCHMARK(BM_GrblStreaming)
    ->Args({1, 0})
    ->Args({0, 0})
    ->Args({1, 2})
    ->Args({0, 2})
    ->Args({1, 16})
    ->Args({0, 16})
    ->ArgNames({"counting", "latency_ms"})
    ->UseManualTime()
    ->Iterations(2)
    ->Unit(benchmark::kSecond);

// A sheet of N short strokes sent to the simulated Ruida over loopback UDP
// (its machine far faster than real): the job's bytes, its packets (one in
// flight, each acknowledged) and the time from the first packet to the
// last acknowledgement.
void BM_RuidaSending(benchmark::State& state) {
  const jobs::Toolpath path = manyStrokes(static_cast<int>(state.range(0)));
  size_t bytes = 0, packets = 0;
  double seconds = 0;
  for (auto _ : state) {
    devices::sim::RuidaSimulatorOptions options;
    options.timeScale = 1e5;
    devices::sim::RuidaSimulator simulator(options);
    devices::ruida::RuidaDriver driver(
        [port = simulator.port()] {
          return devices::ruida::udpChannel(devices::DatagramLink::open("127.0.0.1", port, 0),
                                            devices::ruida::kDefaultMagic);
        },
        devices::ruida::kDefaultMagic, {});
    driver.connect();
    const size_t before = driver.packets();
    std::chrono::steady_clock::time_point started, sent;
    const auto progress = [&](const devices::Progress& p) {
      if (started == std::chrono::steady_clock::time_point()) started = std::chrono::steady_clock::now();
      if (p.bytesAcknowledged == p.bytesTotal && sent == std::chrono::steady_clock::time_point()) {
        sent = std::chrono::steady_clock::now();
        bytes = p.bytesTotal;
        packets = driver.packets() - before;
      }
    };
    driver.run(path, progress, rotafab::core::Cancellation());
    const double elapsed = std::chrono::duration<double>(sent - started).count();
    state.SetIterationTime(elapsed);
    seconds = elapsed;
  }
  state.counters["bytes"] = static_cast<double>(bytes);
  state.counters["packets"] = static_cast<double>(packets);
  state.counters["bytes/s"] = static_cast<double>(bytes) / seconds;
}
BENCHMARK(BM_RuidaSending)
    ->Arg(400)
    ->Arg(4000)
    ->ArgName("strokes")
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
