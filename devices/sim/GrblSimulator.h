#pragma once
// A simulated GRBL 1.1h laser controller on a pseudo-terminal: the
// driver opens its /dev/pts/N as it would /dev/ttyUSB0, so the real serial
// code runs. It behaves as the firmware (gnea/grbl) does where a driver can
// tell: the banner, `$$`, `$I` ([OPT:V,15,128]), a 128-byte receive buffer
// that loses what overflows it, a 15-block planner (a line leaves the
// buffer, and is acknowledged, only when the planner has room), motion as
// GRBL's planner makes it (accelerations, corners at the junction
// deviation's speed, look-ahead over the blocks planned; toolpath/MotionPlan.h),
// sped up by `timeScale`; a spindle change (M3, M4, M5, or an S alone in
// laser mode) acknowledged only once the motion before it has ended;
// realtime `?`, `!`, `~` and 0x18; status reports with the WCO, Ov, A and
// Pn fields as the firmware's counters add them; `error:8` for `$`
// commands while it moves; `error:N` for what it does not take; alarms; and
// laser mode (the laser is lit only during G1 motion under M3/M4 with S > 0,
// never in a hold).
// Faults can be injected: unplug, stop answering, garbage bytes, a garbled
// status report, a stall (it says Run and never moves), an alarm.

#include <array>
#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace rotafab::devices::sim {

struct GrblSimulatorOptions {
  double timeScale = 1.0;  // simulated seconds per real second
  bool laserMode = true;   // $32
  double maxSpindle = 1000;
  double maxRate = 6000;            // $110, $111 mm/min
  double acceleration = 500;        // $120, $121 mm/s^2
  double junctionDeviation = 0.01;  // $11 mm
  size_t receiveBuffer = 128;       // as [OPT:] reports it, and holds
  size_t plannerBlocks = 15;
  unsigned baud = 0;  // > 0: bytes from the driver arrive no faster than this serial line carries (10 bits a byte)
  std::chrono::milliseconds replyLatency{0};  // each reply reaches the driver this much later (a USB adapter's)
  // Told each time the laser goes on or off (from the simulator's thread):
  // a witness outside the process that drives it (sim:grbl?witness=FILE).
  std::function<void(bool lit)> laserChanged;
  // Told each lit move the machine finished, from (x, y) to (x, y) in mm
  // (from the simulator's thread): what was cut (sim:grbl?cuts=FILE).
  std::function<void(const std::array<double, 4>& move)> litMoveFinished;
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
  // On the simulated clock (seconds since it started): when the first
  // move entered the planner, and when the planner last emptied.
  double motionStartedAt = -1, motionEndedAt = -1;
  double topSpeed = 0;  // mm/s, the fastest the head moved
  // Every lit move the machine finished, from (x, y) to (x, y), mm: what was cut.
  std::vector<std::array<double, 4>> litMoves;
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
  void unplug();                   // the port goes away (the master side closes)
  void mute(bool silent);          // stops reading and answering, as a hung controller
  void sendGarbage();              // bytes no GRBL sends
  void raiseAlarm(int code);       // e.g. 1: a hard limit; motion stops, the laser goes off
  void loseNextOk();               // the next `ok` never arrives (line noise)
  void garbleNextStatus();         // the next status report arrives with bytes changed (line noise)
  void stall();                    // motion stops and nothing more is taken, yet it reports Run (until a reset)
  void setPins(std::string pins);  // input pins reported active (Pn:), e.g. "P" for the probe
  void afterLines(size_t lines, std::function<void(GrblSimulator&)> fault);  // inject once that many lines ran

 private:
  // The laser's state now, with laserChanged told of a change.
  void setLaser(bool lit);
  void loop();
  void receive(char byte);
  void takeLines();
  void executeLine(const std::string& line);
  void advance(double seconds);
  void reply(const std::string& text);
  void reset();
  std::string statusReport();
  bool needsSync(const std::string& line) const;
  void replan();

  struct Block {
    double x, y;  // target (mm)
    bool lit;
    double length, nominal, acceleration;  // mm, mm/s, mm/s^2
    double unitX, unitY;
    double maxEntrySquared;
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
  double blockDone_ = 0;  // mm of the first block covered
  double speed_ = 0;      // mm/s, now
  double exitSpeed_ = 0;  // mm/s: what the first block must slow to by its end (the look-ahead's)
  double clock_ = 0;      // simulated seconds
  double lastUnitX_ = 0, lastUnitY_ = 0;
  std::optional<std::string> syncing_;  // a line waiting for the motion before it to end
  bool stalled_ = false, garbleStatus_ = false;
  std::string pins_;
  int wcoCounter_ = 0, overrideCounter_ = 0;
  int spindleMode_ = 5;             // 3, 4 or 5, as the last M word
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
