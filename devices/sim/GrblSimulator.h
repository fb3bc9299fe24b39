#pragma once
// A simulated GRBL 1.1 laser controller on a pseudo-terminal: the
// driver opens its /dev/pts/N as it would /dev/ttyUSB0, so the real serial
// code runs. It behaves as GRBL does where a driver can tell: the banner,
// `$$`, `$I` ([OPT:V,15,128]), a 127-byte receive buffer that loses what
// overflows it, a 15-block planner (a line leaves the buffer, and is
// acknowledged, only when the planner has room), motion at the commanded
// feed (sped up by `timeScale`), realtime `?`, `!`, `~` and 0x18, status
// reports, `error:N` for what it does not take, alarms, and laser mode (the
// laser is lit only during G1 motion under M3/M4 with S > 0, never in a hold).
// Faults can be injected: unplug, stop answering, garbage bytes, an alarm.

#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace rotafab::devices::sim {

struct GrblSimulatorOptions {
  double timeScale = 1.0;  // simulated seconds per real second
  bool laserMode = true;   // $32
  double maxSpindle = 1000;
  double maxRate = 6000;       // $110, $111 mm/min
  double acceleration = 500;   // $120, $121 mm/s^2
  size_t receiveBuffer = 128;  // as [OPT:] reports it; holds one byte less
  size_t plannerBlocks = 15;
  unsigned baud = 0;  // > 0: bytes from the driver arrive no faster than this serial line carries (10 bits a byte)
  std::chrono::milliseconds replyLatency{0};  // each reply reaches the driver this much later (a USB adapter's)
};

// What a test checks after a run.
struct GrblSimulatorRecord {
  size_t mostBuffered = 0;         // most bytes ever waiting in the receive buffer
  bool overflowed = false;         // a byte arrived when the buffer was full (GRBL would lose it)
  size_t linesExecuted = 0;        // G-code lines taken into the planner
  bool laserOn = false;            // now
  bool spindleEnabled = false;     // M3/M4 in effect now (M5 clears it)
  double litSeconds = 0;           // simulated seconds with the laser lit
  std::vector<std::string> lines;  // every line taken from the buffer, in order
  std::string state;               // "Idle", "Run", "Hold:0", "Alarm"
  double x = 0, y = 0;             // mm
};

class GrblSimulator {
 public:
  explicit GrblSimulator(GrblSimulatorOptions options = {});
  ~GrblSimulator();
  GrblSimulator(const GrblSimulator&) = delete;
  GrblSimulator& operator=(const GrblSimulator&) = delete;

  // The pseudo-terminal to open, e.g. /dev/pts/3.
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] GrblSimulatorRecord record() const;

  // Faults.
  void unplug();              // the port goes away (the master side closes)
  void mute(bool silent);     // stops reading and answering, as a hung controller
  void sendGarbage();         // bytes no GRBL sends
  void raiseAlarm(int code);  // e.g. 1: a hard limit; motion stops, the laser goes off
  void loseNextOk();          // the next `ok` never arrives (line noise)
  void afterLines(size_t lines, std::function<void(GrblSimulator&)> fault);  // inject once that many lines ran

 private:
  void loop();
  void receive(char byte);
  void takeLines();
  void executeLine(const std::string& line);
  void advance(double seconds);
  void reply(const std::string& text);
  void reset();
  std::string statusReport() const;

  struct Block {
    double x, y, feed;  // target (mm) and mm/min
    bool lit;
  };
  GrblSimulatorOptions options_;
  int master_ = -1, slave_ = -1;
  std::string path_;
  std::thread thread_;
  std::atomic<bool> stopping_{false}, muted_{false}, unplugged_{false}, loseOk_{false};
  mutable std::recursive_mutex mutex_;
  GrblSimulatorRecord record_;
  std::string buffer_;  // the receive buffer
  std::vector<Block> planner_;
  double blockDone_ = 0;            // mm of the first block covered
  double startX_ = 0, startY_ = 0;  // where the first block started
  bool held_ = false, alarm_ = false, laserModal_ = false;
  double holdSettle_ = 0;  // simulated seconds until a hold has stopped the machine (Hold:1, then Hold:0)
  std::atomic<bool> unplugRequested_{false};
  double feed_ = 0, spindle_ = 0;
  bool feedSet_ = false, rapid_ = true;
  size_t faultAfter_ = 0;
  std::chrono::steady_clock::time_point paced_ = std::chrono::steady_clock::now();
  std::deque<std::pair<std::chrono::steady_clock::time_point, std::string>> delayed_;  // replies on their way
  void writeNow(const std::string& text);
  std::function<void(GrblSimulator&)> fault_;
};

}  // namespace rotafab::devices::sim
