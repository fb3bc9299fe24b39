#pragma once
// A Ruida controller on loopback UDP, for sim:ruida and the tests: it
// speaks the controller's own bytes (devices/ruida/RuidaCodec.h) to the
// real driver through the real transport. It checks every packet's
// checksum and answers ACK or NAK (swizzled), puts the commands back
// together across packets, answers memory reads (status, position, bed,
// card ID), and runs the job as it arrives: each move and cut in
// simulated time, the laser lit only while it cuts, paused (laser off),
// resumed and stopped by the controller's commands. It can be told to drop
// a packet, corrupt one (its checksum then fails) or stop answering, as a
// controller on a bad network or one switched off does.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "devices/ruida/RuidaCodec.h"
#include "devices/ruida/RuidaJob.h"

namespace rotafab::devices::sim {

enum class RuidaFault { None, Drop, Corrupt, Silence };

struct RuidaSimulatorOptions {
  double timeScale = 50;  // simulated seconds per real second
  uint8_t magic = ruida::kDefaultMagic;
  double bedWidth = 812.8, bedHeight = 457.2;  // mm (the default machine's 32 x 18 in bed)
  double travelSpeed = 400;                    // mm/s, for moves with the laser off
  // The fault, at the packet numbered `after` (from 1): that one dropped
  // (no answer) or corrupted once, or from it on no answer at all (and the
  // job halted, the laser off, as a controller switched off).
  RuidaFault fault = RuidaFault::None;
  // Whether its status says a job runs (bit 0); off: only the moving head says it.
  bool reportsJobs = true;
  size_t after = 5;
  std::function<void(bool lit)> laserChanged;
  // Each cut finished: x0, y0, x1, y1 in mm from the machine's origin (top-left, y down).
  std::function<void(const std::array<double, 4>& cut)> cutFinished;
};

struct RuidaCut {
  double x0, y0, x1, y1;  // mm, machine frame
  double power;           // 0..1
};

class RuidaSimulator {
 public:
  explicit RuidaSimulator(RuidaSimulatorOptions options = {});
  ~RuidaSimulator();
  RuidaSimulator(const RuidaSimulator&) = delete;
  RuidaSimulator& operator=(const RuidaSimulator&) = delete;

  [[nodiscard]] uint16_t port() const { return port_; }
  [[nodiscard]] bool laserOn() const { return laserOn_; }
  [[nodiscard]] bool jobRuns() const;
  // What has happened, for the tests.
  [[nodiscard]] std::vector<RuidaCut> cuts() const;
  [[nodiscard]] size_t packets() const { return packets_; }
  [[nodiscard]] size_t naks() const { return naks_; }
  [[nodiscard]] size_t stops() const { return stops_; }
  [[nodiscard]] size_t pauses() const { return pauses_; }
  // Commands it could not read (a job cut short, a command it does not know is not one).
  [[nodiscard]] std::vector<std::string> errors() const;

 private:
  struct Segment {
    double x0, y0, x1, y1;  // micrometres
    bool lit;
    double power, speed;  // 0..1, micrometres a second
  };
  void serve();
  void receive(const ruida::Bytes& datagram, const void* from, unsigned fromLength);
  void command(const ruida::Bytes& command, const void* from, unsigned fromLength);
  void advance(double seconds);
  void setLaser(bool lit);
  int64_t memory(uint16_t address) const;

  RuidaSimulatorOptions options_;
  ruida::Swizzle swizzle_;
  int socket_ = -1;
  uint16_t port_ = 0;
  std::thread thread_;
  std::atomic<bool> quit_{false};
  std::atomic<bool> laserOn_{false};
  std::atomic<size_t> packets_{0}, naks_{0}, stops_{0}, pauses_{0};
  bool faultDone_ = false, silent_ = false;

  mutable std::mutex mutex_;  // what follows, between the simulator's thread and the tests'
  ruida::Bytes pending_;      // the start of a command that goes on in the next packet
  ruida::JobReader reader_;
  bool jobStarted_ = false, jobEnded_ = false, paused_ = false;
  std::vector<Segment> queue_;
  size_t next_ = 0;       // the segment being run
  double into_ = 0;       // seconds of it run
  double x_ = 0, y_ = 0;  // the head, micrometres
  std::vector<RuidaCut> cuts_;
  std::vector<std::string> errors_;
};

}  // namespace rotafab::devices::sim
