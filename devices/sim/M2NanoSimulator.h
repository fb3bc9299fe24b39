#pragma once
// A simulated Lihuiyu M2 Nano (K40) on USB, plugged into libusb
// through umockdev: a testbed device 1a86:5512 (the CH341 bridge in
// parallel mode) whose usbfs requests (claim, control and bulk transfers,
// reaping, discarding) this simulator answers, so that the real libusb code
// path of the driver runs, byte for byte as with a K40. Behind the bridge, a
// board (LhymicroBoard) takes the 34-byte packets, checks their CRC, queues a
// few of them and runs them at the coded speeds (sped up by `timeScale`),
// and answers status requests: 206 OK, 238 busy (checking a packet, or its
// queue full), 207 CRC error, 236 finished, 239 power fault. Faults can be
// injected: unplug, stop answering, corrupted packets, garbage, power fault.
//
// umockdev works by a preloaded library: the process must run under it
// (runUnderUmockdev()). One simulator at a time in a process.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "devices/sim/LhymicroBoard.h"
#include "devices/transport/UsbLink.h"

namespace rotafab::devices::sim {

struct M2NanoSimulatorOptions {
  double timeScale = 1.0;  // simulated seconds per real second
  LhymicroBoard::Options board;
};

// What a test checks after a run.
struct M2NanoSimulatorRecord {
  bool initialised = false;  // the CH341's parallel-mode control transfer arrived
  size_t packetsAccepted = 0, packetsRejected = 0, statusRequests = 0;
  std::vector<std::string> payloads;  // every accepted packet's 30 bytes, in order
  bool laser = false, busy = false;
  BoardMode mode = BoardMode::Default;
  long x = 0, y = 0;  // mils
  std::vector<BoardSegment> trace;
  std::vector<std::string> violations;
};

class M2NanoSimulator {
 public:
  // Throws std::runtime_error when umockdev's preload library is not loaded.
  explicit M2NanoSimulator(M2NanoSimulatorOptions options = {});
  ~M2NanoSimulator();
  M2NanoSimulator(const M2NanoSimulator&) = delete;
  M2NanoSimulator& operator=(const M2NanoSimulator&) = delete;

  // What the driver opens: 1a86:5512 on bus 1, address 4 of the testbed.
  [[nodiscard]] UsbMatch match() const;
  [[nodiscard]] M2NanoSimulatorRecord record() const;

  // Faults.
  void unplug();                      // every request fails as the kernel's do once the device is gone
  void mute(bool silent);             // status requests go unanswered (a hung board)
  void corruptPackets(size_t count);  // the next `count` packets arrive corrupted (status 207)
  void sendGarbage();                 // the next status reply is no status a board sends
  void powerFault(bool on);           // status 239
  // Runs `fault` once, when that many packets have been accepted (from the USB thread).
  void afterPackets(size_t packets, std::function<void(M2NanoSimulator&)> fault);

  struct State;

 private:
  std::unique_ptr<State> state_;
};

// Whether umockdev's preload library is loaded in this process.
bool umockdevPreloaded();
// Runs this program again, from the start, with umockdev's preload library
// (as umockdev-wrapper does), unless it is loaded already; returns only then.
// Throws std::runtime_error when that cannot be done.
void runUnderUmockdev(char** argv);

}  // namespace rotafab::devices::sim
