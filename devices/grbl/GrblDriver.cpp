#include "devices/grbl/GrblDriver.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <regex>
#include <thread>

#include "devices/grbl/CutTracker.h"
#include "devices/grbl/GrblCodes.h"

namespace rotafab::devices::grbl {
namespace {

constexpr char kStatus = '?', kHold = '!', kResume = '~', kReset = 0x18;

bool isBanner(const std::string& line) { return line.starts_with("Grbl ") || line.starts_with("GrblHAL "); }

int codeAfter(const std::string& line, size_t prefix) {
  try {
    return std::stoi(line.substr(prefix));
  } catch (const std::exception&) {
    return -1;
  }
}

// An `ALARM:N` line, and an `error:N` reply to `command`, as the faults they are.
DeviceFault alarmFault(const std::string& device, const std::string& line) {
  return DeviceFault(FaultKind::Alarm, fmt::format("{}: {}", device, alarmMessage(codeAfter(line, 6))));
}
DeviceFault errorFault(const std::string& device, const std::string& command, const std::string& reply) {
  return DeviceFault(FaultKind::Error, fmt::format("{}: {}: {}", device, command, errorMessage(codeAfter(reply, 6))));
}

// Lines in a row that are no GRBL reply before the link is taken for broken:
// a USB serial link garbles a byte now and then, and a report or an `ok`
// lost to it is not a fault by itself (a lost `ok` is found otherwise).
constexpr int kGarbledRun = 3;
// The feed a marking frame is traced at, mm/min: quick to follow by eye, and
// with the power a few percent, a dot that marks nothing.
constexpr int kFrameFeed = 3000;

// What the controller said, shown safely: printable ASCII, at most 40 bytes.
std::string shown(const std::string& line) {
  std::string text;
  for (char c : line.substr(0, 40)) text += (c >= 32 && c < 127) ? c : '?';
  return text;
}

// A machine that says Run yet neither moves nor acknowledges: a stall.
// Progress is an `ok`, or a position that changed, or any other state.
class StallWatch {
 public:
  explicit StallWatch(std::chrono::steady_clock::duration bound) : bound_(bound) {}
  void progressed() { since_ = std::chrono::steady_clock::now(); }
  // Whether the report shows a stall.
  bool stalled(const DeviceStatus& report) {
    const auto now = std::chrono::steady_clock::now();
    if (report.state != "Run" || std::abs(report.x - x_) > 1e-7 || std::abs(report.y - y_) > 1e-7) {
      x_ = report.x, y_ = report.y, since_ = now;
      return false;
    }
    return now - since_ > bound_;
  }
  [[nodiscard]] double seconds() const { return std::chrono::duration<double>(bound_).count(); }
  void setBound(std::chrono::steady_clock::duration bound) { bound_ = bound; }

 private:
  std::chrono::steady_clock::duration bound_;
  std::chrono::steady_clock::time_point since_ = std::chrono::steady_clock::now();
  double x_ = 1e300, y_ = 1e300;
};

DeviceFault stallFault(const std::string& device, const DeviceStatus& report, double seconds) {
  return DeviceFault(FaultKind::Stalled,
                     fmt::format("{}: the machine stopped moving: it says Run, yet it has stood at ({:.3f}, {:.3f}) "
                                 "mm for {:.0f} s without taking a line; check the motors and their drivers",
                                 device, report.x * kMillimetresPerInch, report.y * kMillimetresPerInch, seconds));
}

// The longest a stall may look like motion: twice the slowest move that can
// be in the planner (GRBL's 15 blocks, or the lines from `first` on), at
// least `floor`, at most 30 s.
std::chrono::milliseconds stallBound(const std::vector<double>& moveEnds, const GCodeProgram& program, size_t first,
                                     size_t last, Millis floor, double timeScale) {
  double longest = 0;
  for (size_t line = first; line < last && line < program.lines.size(); ++line) {
    const int move = program.lineMove[line];
    if (move < 0) continue;
    longest = std::max(longest, moveEnds[move] - (move > 0 ? moveEnds[move - 1] : 0.0));
  }
  const auto bound = std::chrono::milliseconds(static_cast<long long>(2000 * longest / timeScale));
  return std::min<std::chrono::milliseconds>(std::max<std::chrono::milliseconds>(bound, floor),
                                             std::chrono::milliseconds(30000));
}

}  // namespace

std::optional<DeviceStatus> parseStatusReport(const std::string& line) {
  static const std::regex report(R"(^<([A-Za-z]+(?::\d+)?)\|[MW]Pos:(-?[0-9.]+),(-?[0-9.]+)(?:,(-?[0-9.]+))?.*>$)");
  std::smatch m;
  if (!std::regex_match(line, m, report)) return std::nullopt;
  try {
    return DeviceStatus{m[1], std::stod(m[2]) / kMillimetresPerInch, std::stod(m[3]) / kMillimetresPerInch};
  } catch (const std::exception&) {  // "." and the like
    return std::nullopt;
  }
}

GrblDriver::GrblDriver(std::function<std::unique_ptr<Link>()> open, GrblTimeouts timeouts, double timeScale)
    : open_(std::move(open)), timeouts_(timeouts), timeScale_(timeScale) {}

std::string GrblDriver::expectLine(Millis timeout, const char* waitingFor) {
  auto line = link_->readLine(timeout);
  if (!line) {
    throw DeviceFault(FaultKind::Timeout, fmt::format("{}: no answer within {} ms while waiting for {}", link_->name(),
                                                      timeout.count(), waitingFor));
  }
  return *line;
}

std::string GrblDriver::connect() {
  // The link is kept only once the controller has answered as a GRBL in
  // laser mode: a half-set-up one would let run() and status() skip
  // connecting, and would hold the port open.
  link_.reset();
  struct Keep {
    std::unique_ptr<Link>& link;
    bool connected = false;
    ~Keep() {
      if (connected || !link) return;
      link->close();
      link.reset();
    }
  } keep{link_};
  link_ = open_();
  // An Arduino resets when its port opens and prints the banner; a board
  // reached over TCP does not, so it is reset once.
  std::string banner;
  for (int attempt = 0; attempt < 2 && banner.empty(); ++attempt) {
    const auto until = std::chrono::steady_clock::now() + timeouts_.banner / 2;
    while (banner.empty() && std::chrono::steady_clock::now() < until) {
      const auto line = link_->readLine(Millis(100));
      if (line && isBanner(*line)) banner = *line;
    }
    if (banner.empty() && attempt == 0) link_->write(std::string(1, kReset), timeouts_.answer);
  }
  if (banner.empty()) {
    throw DeviceFault(FaultKind::Protocol,
                      fmt::format("{}: no GRBL banner (\"Grbl 1.1h ['$' for help]\") within {} ms: is this a GRBL "
                                  "controller, at the right baud rate?",
                                  link_->name(), timeouts_.banner.count()));
  }
  // $$: "$32=1" lines, then ok.
  settings_.clear();
  link_->write("$$\n", timeouts_.answer);
  for (;;) {
    const std::string line = expectLine(timeouts_.answer, "the settings ($$)");
    if (line == "ok") break;
    if (line.starts_with("error:")) throw errorFault(link_->name(), "$$", line);
    static const std::regex setting(R"(^\$(\d+)=(-?[0-9.]+))");
    std::smatch m;
    if (std::regex_search(line, m, setting)) settings_[std::stoi(m[1])] = std::stod(m[2]);
  }
  // $I: [VER:...] and [OPT:flags,blocks,rx bytes], then ok.
  receiveBuffer_ = 128, plannerBlocks_ = 15;
  link_->write("$I\n", timeouts_.answer);
  for (;;) {
    const std::string line = expectLine(timeouts_.answer, "the build info ($I)");
    if (line == "ok") break;
    static const std::regex options(R"(^\[OPT:[^,\]]*,(\d+),(\d+))");
    std::smatch m;
    if (std::regex_search(line, m, options)) plannerBlocks_ = std::stoul(m[1]), receiveBuffer_ = std::stoul(m[2]);
  }
  if (!settings_.count(32)) {
    throw DeviceFault(FaultKind::Refused,
                      fmt::format("{}: the controller has no laser mode ($32 missing from $$): GRBL 1.1 or later is "
                                  "needed, as older firmware keeps the laser on through rapid moves",
                                  link_->name()));
  }
  if (settings_[32] != 1) {
    throw DeviceFault(FaultKind::Refused,
                      fmt::format("{}: laser mode is off ($32={}): with it off GRBL stops at every S change and "
                                  "keeps the laser on through rapid moves; send $32=1 to the controller (in a serial "
                                  "terminal) and run again",
                                  link_->name(), settings_[32]));
  }
  if (receiveBuffer_ < 81) {
    throw DeviceFault(FaultKind::Protocol, fmt::format("{}: [OPT:] reports a receive buffer of {} bytes; a line of "
                                                       "80 would never fit",
                                                       link_->name(), receiveBuffer_));
  }
  keep.connected = true;
  return fmt::format("{} (receive buffer {} bytes, laser mode on)", banner, receiveBuffer_);
}

GCodeOptions GrblDriver::gcodeOptions() const {
  GCodeOptions options;
  if (const auto it = settings_.find(30); it != settings_.end() && it->second > 0) options.maxSpindle = it->second;
  return options;
}

std::string GrblDriver::program(const std::vector<jobs::Toolpath>& toolpaths) const {
  std::string bytes;
  for (const jobs::Toolpath& toolpath : toolpaths) {
    for (const std::string& line : gcodeLines(toolpath, gcodeOptions())) bytes.append(line).append("\n");
  }
  return bytes;
}

std::string GrblDriver::describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const {
  size_t strokes = 0;
  for (const jobs::Toolpath& toolpath : toolpaths) strokes += toolpath.strokes.size();
  return fmt::format("G-code for {} sheet{} ({} strokes), as the driver would send it", toolpaths.size(),
                     toolpaths.size() == 1 ? "" : "s", strokes);
}

jobs::MotionLimits GrblDriver::motionLimits() const {
  jobs::MotionLimits limits;
  const auto get = [&](int key) {
    const auto it = settings_.find(key);
    return it == settings_.end() ? 0.0 : it->second;
  };
  // The slower axis bounds a move in any direction.
  const double rate = std::min(get(110), get(111)), accel = std::min(get(120), get(121));
  if (rate > 0) limits.maxSpeed = rate / kMillimetresPerInch / 60;
  if (accel > 0) limits.acceleration = accel / kMillimetresPerInch;
  // GRBL's planner: look-ahead through corners of $11's deviation, each axis at its own limits.
  limits.junctionDeviation = (settings_.count(11) ? get(11) : 0.01) / kMillimetresPerInch;
  limits.perAxis = true;
  return limits;
}

void GrblDriver::send(const std::string& line) {
  link_->write(line + "\n", timeouts_.answer);
  for (;;) {
    const std::string reply = expectLine(timeouts_.answer, line.c_str());
    if (reply == "ok") return;
    if (reply.starts_with("error:")) throw errorFault(link_->name(), fmt::format("`{}`", line), reply);
    if (reply.starts_with("ALARM:")) throw alarmFault(link_->name(), reply);
  }
}

void GrblDriver::home() {
  if (!link_) connect();
  try {
    link_->write("$H\n", timeouts_.answer);
    for (;;) {
      const std::string reply = expectLine(timeouts_.homing, "homing ($H)");
      if (reply == "ok") return;
      if (reply.starts_with("error:")) {
        DeviceFault fault = errorFault(link_->name(), "$H", reply);
        if (codeAfter(reply, 6) == 5) fault.kind = FaultKind::Refused;  // homing is off ($22=0)
        throw fault;
      }
      if (reply.starts_with("ALARM:")) throw alarmFault(link_->name(), reply);
    }
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

DeviceStatus GrblDriver::status() {
  if (!link_) connect();
  link_->write(std::string(1, kStatus), timeouts_.answer);
  for (;;) {
    const std::string line = expectLine(timeouts_.answer, "a status report");
    if (auto report = parseStatusReport(line)) return *report;
  }
}

void GrblDriver::waitIdle(Millis silence, const core::Cancellation* cancel, Millis stallAfter,
                          const std::function<void(const std::string&)>& reported) {
  // As long as status reports come and the position changes, the machine is working (or held).
  bool idleBefore = false;
  StallWatch stall(stallAfter);
  for (;;) {
    if (cancel && cancel->cancelled()) throw DeviceFault(FaultKind::Cancelled, link_->name() + ": cancelled");
    if (holdRequested_.exchange(false)) link_->write(std::string(1, kHold), timeouts_.answer);
    if (resumeRequested_.exchange(false)) link_->write(std::string(1, kResume), timeouts_.answer);
    link_->write(std::string(1, kStatus), timeouts_.answer);
    const auto until = std::chrono::steady_clock::now() + silence;
    std::optional<DeviceStatus> report;
    while (!report) {
      const auto line = link_->readLine(timeouts_.poll);
      if (!line) {
        if (std::chrono::steady_clock::now() > until) {
          throw DeviceFault(FaultKind::Timeout,
                            fmt::format("{}: no status report within {} ms", link_->name(), silence.count()));
        }
        link_->write(std::string(1, kStatus), timeouts_.answer);
        continue;
      }
      if (line->starts_with("ALARM:")) throw alarmFault(link_->name(), *line);
      report = parseStatusReport(*line);
      if (report && reported) reported(*line);
    }
    // Two Idle reports in a row: one may have been on its way from before the last lines ran.
    if (report->state == "Idle" && idleBefore) return;
    idleBefore = report->state == "Idle";
    if (report->state.starts_with("Alarm")) {
      throw DeviceFault(FaultKind::Alarm, link_->name() + ": the controller is in alarm");
    }
    if (stall.stalled(*report)) throw stallFault(link_->name(), *report, stall.seconds());
    std::this_thread::sleep_for(timeouts_.poll);
  }
}

void GrblDriver::frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) {
  if (!link_) connect();
  const auto box = toolpathBounds(toolpath);
  const auto mm = [](double inches) { return jobs::formatDecimal(inches * kMillimetresPerInch, 3); };
  // At the machine's marking power, where its profile gives one (a dot to
  // see by), else with the laser off.
  const bool marking = toolpath.framePower > 0;
  try {
    send("M5 S0");
    send("G21");
    send("G90");
    // M4 before any motion: GRBL acknowledges M3/M4/M5 only once its planner
    // has drained. In laser mode G0 is never lit and M4 scales the power with
    // the speed, so the laser is dark at the corners and while it stands.
    if (marking) {
      send(fmt::format("M4 S{}", jobs::formatDecimal(toolpath.framePower / 100 * gcodeOptions().maxSpindle, 1)));
    }
    const std::pair<double, double> corners[] = {
        {box[0], box[1]}, {box[2], box[1]}, {box[2], box[3]}, {box[0], box[3]}, {box[0], box[1]}};
    send(fmt::format("G0 X{} Y{}", mm(corners[0].first), mm(corners[0].second)));
    for (size_t c = 1; c < std::size(corners); ++c) {
      send(marking ? fmt::format("G1 X{} Y{} F{}", mm(corners[c].first), mm(corners[c].second), kFrameFeed)
                   : fmt::format("G0 X{} Y{}", mm(corners[c].first), mm(corners[c].second)));
    }
    waitIdle(timeouts_.answer, &cancel);
    if (marking) send("M5 S0");  // (the planner is empty: acknowledged at once)
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

void GrblDriver::run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
                     const core::Cancellation& cancel) {
  if (!link_) connect();
  const GCodeProgram program = gcodeProgram(toolpath, gcodeOptions());
  const std::vector<std::string>& lines = program.lines;
  // The time each move ends, as GRBL's planner runs it with these settings.
  const jobs::MotionTime timing = jobs::toolpathTime(toolpath, motionLimits());
  Progress state;
  state.sheet = toolpath.sheet;
  state.strokes = toolpath.strokes.size();
  state.secondsLeft = timing.seconds;
  for (const std::string& line : lines) state.bytesTotal += line.size() + 1;
  // Character counting: the bytes sent and not yet acknowledged never exceed
  // what the receive buffer holds (one byte of the ring stays free).
  const size_t capacity = receiveBuffer_ - 1;
  std::deque<size_t> inFlight;
  size_t inFlightBytes = 0, next = 0, acknowledged = 0;
  auto lastHeard = std::chrono::steady_clock::now(), lastPoll = lastHeard;
  // Idle with lines sent and unacknowledged, and no `ok` for a while: a reply
  // was lost (or a line), and the job would wait for ever.
  bool idle = false;
  auto idleSince = lastHeard;
  int garbled = 0;
  StallWatch stall(timeouts_.answer);
  CutTracker cut(program, plannerBlocks_);
  // A report that shows the head further on: the strokes behind it are cut.
  const auto placeHead = [&](const std::string& report) {
    const size_t before = cut.strokesCut();
    cut.observe(report, acknowledged);
    if (cut.strokesCut() != before) {
      state.strokesCut = cut.strokesCut();
      if (progress) progress(state);
    }
  };
  holdRequested_ = false, resumeRequested_ = false;  // none left over from an earlier job
  try {
    while (acknowledged < lines.size()) {
      if (cancel.cancelled()) throw DeviceFault(FaultKind::Cancelled, link_->name() + ": cancelled");
      if (holdRequested_.exchange(false)) link_->write(std::string(1, kHold), timeouts_.answer);
      if (resumeRequested_.exchange(false)) link_->write(std::string(1, kResume), timeouts_.answer);
      while (next < lines.size() && inFlightBytes + lines[next].size() + 1 <= capacity &&
             (characterCounting_ || inFlight.empty())) {
        link_->write(lines[next] + "\n", timeouts_.answer);
        inFlight.push_back(lines[next].size() + 1);
        inFlightBytes += lines[next].size() + 1;
        ++next;
      }
      const auto now = std::chrono::steady_clock::now();
      if (now - lastPoll >= timeouts_.poll) {
        link_->write(std::string(1, kStatus), timeouts_.answer);
        lastPoll = now;
      }
      const auto line = link_->readLine(Millis(20));
      if (!line) {
        if (std::chrono::steady_clock::now() - lastHeard > timeouts_.answer) {
          throw DeviceFault(FaultKind::Timeout, fmt::format("{}: no answer for {} ms (not even to status polls)",
                                                            link_->name(), timeouts_.answer.count()));
        }
        continue;
      }
      lastHeard = std::chrono::steady_clock::now();
      const bool report = line->starts_with("<");
      const auto status = report ? parseStatusReport(*line) : std::nullopt;
      const bool understood = *line == "ok" || line->starts_with("error:") || line->starts_with("ALARM:") || status ||
                              isBanner(*line) || line->empty() || line->starts_with("[");
      if (!understood) {
        if (++garbled >= kGarbledRun) {
          throw DeviceFault(FaultKind::Protocol,
                            fmt::format("{}: {} lines in a row that are no GRBL reply (the last: \"{}\"): is the "
                                        "cable sound, and the baud rate right?",
                                        link_->name(), garbled, shown(*line)));
        }
        continue;  // line noise: the next poll brings another report
      }
      garbled = 0;
      if (*line == "ok") {
        if (inFlight.empty()) throw DeviceFault(FaultKind::Protocol, link_->name() + ": an `ok` for no line sent");
        idle = false;  // a reply came: nothing is lost
        stall.progressed();
        inFlightBytes -= inFlight.front();
        state.bytesAcknowledged += inFlight.front();
        inFlight.pop_front();
        if (const int move = program.lineMove[acknowledged]; move >= 0) {
          state.secondsLeft = std::max(0.0, timing.seconds - timing.endsAt[move]);
        }
        ++acknowledged;
        cut.acknowledged(acknowledged);
        state.strokesCut = cut.strokesCut();
        state.stroke =
            static_cast<size_t>(std::upper_bound(program.strokeEnds.begin(), program.strokeEnds.end(), acknowledged) -
                                program.strokeEnds.begin());
        if (acknowledged == lines.size()) state.secondsLeft = 0;
        if (progress) progress(state);
      } else if (line->starts_with("error:")) {
        throw errorFault(link_->name(), fmt::format("line {} `{}`", acknowledged + 1, lines[acknowledged]), *line);
      } else if (line->starts_with("ALARM:")) {
        throw alarmFault(link_->name(), *line);
      } else if (status) {
        if (status->state.starts_with("Alarm")) {
          throw DeviceFault(FaultKind::Alarm, link_->name() + ": the controller went into alarm");
        }
        placeHead(*line);
        if (status->state == "Idle" && !inFlight.empty()) {
          if (!idle) idle = true, idleSince = std::chrono::steady_clock::now();
          if (std::chrono::steady_clock::now() - idleSince > timeouts_.answer) {
            throw DeviceFault(
                FaultKind::Timeout,
                fmt::format("{}: idle with {} line{} unanswered for {} ms: a reply was lost", link_->name(),
                            inFlight.size(), inFlight.size() == 1 ? "" : "s", timeouts_.answer.count()));
          }
        } else {
          idle = false;
        }
        // The planner holds at most the lines acknowledged lately; the slowest of them bounds an honest pause.
        const size_t planned = acknowledged > plannerBlocks_ ? acknowledged - plannerBlocks_ : 0;
        stall.setBound(stallBound(timing.endsAt, program, planned, next, timeouts_.answer, timeScale_));
        if (stall.stalled(*status)) throw stallFault(link_->name(), *status, stall.seconds());
      } else if (isBanner(*line)) {
        throw DeviceFault(FaultKind::Protocol, link_->name() + ": the controller reset itself mid-job");
      }
    }
    // Every line is in the planner: wait for the motion to end.
    waitIdle(timeouts_.answer, &cancel,
             stallBound(timing.endsAt, program, lines.size() > plannerBlocks_ ? lines.size() - plannerBlocks_ : 0,
                        lines.size(), timeouts_.answer, timeScale_),
             placeHead);
    cut.finished();
    state.strokesCut = cut.strokesCut();
    if (progress) progress(state);
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

bool GrblDriver::stopSafely() noexcept {
  if (!link_) return false;
  try {
    link_->write(std::string(1, kHold), Millis(500));
    // Wait for the machine to stand still (Hold:0, or Idle): a reset while
    // it moves would stop it as well, but lose its position (ALARM:3).
    const auto still = std::chrono::steady_clock::now() + timeouts_.stopHold;
    while (std::chrono::steady_clock::now() < still) {
      link_->write(std::string(1, kStatus), Millis(500));
      const auto line = link_->readLine(Millis(100));
      const auto report = line ? parseStatusReport(*line) : std::nullopt;
      // (Idle is no proof: a report on its way from before the hold can say it while the machine moves.)
      if (report && (report->state == "Hold:0" || report->state.starts_with("Alarm"))) break;
    }
    link_->write(std::string(1, kReset), Millis(500));
    // The reset stops the spindle (the laser); once the banner is back, say it again.
    const auto until = std::chrono::steady_clock::now() + timeouts_.stopReset;
    bool answered = false;
    while (!answered && std::chrono::steady_clock::now() < until) {
      const auto line = link_->readLine(Millis(100));
      answered = line && isBanner(*line);
    }
    if (!answered) return false;
    link_->write("M5 S0\n", Millis(500));
    // ok, or error:9 in an alarm: the laser is off either way.
    for (int i = 0; i < 10; ++i) {
      const auto line = link_->readLine(Millis(300));
      if (!line) return false;
      if (*line == "ok" || line->starts_with("error:")) return true;
    }
    return false;
  } catch (...) {
    return false;  // the link is gone: nothing more can be said to the controller
  }
}

void GrblDriver::disconnect() {
  if (link_) link_->close();
  link_.reset();
}

}  // namespace rotafab::devices::grbl
