#pragma once
// The command interpreter of a simulated Lihuiyu M2 Nano board (K40 lasers):
// it executes the LHYMICRO-GL bytes of accepted packets the way MeerK40t's
// board emulator reads them (the protocol notes, sections 4 and 8.4), on a
// clock the caller advances, so that a USB simulator can stand in for the
// board and tests can check what the machine did: every move with its laser
// state and speed, the modes, and the rules a driver must never break.
//
// Where the notes leave the board's behaviour open, the choices are:
// - A packet that is only "I" (then 'F' padding) is an abort, taken at once:
//   it drops every queued packet and stops the move in progress where the
//   head is (K40 Whisperer sends it without waiting; queued behind the job it
//   would abort nothing). An 'I' inside a longer packet resets in turn.
//   Whether a real board takes it at once is not documented: with
//   `abortAtOnce` off, it waits its turn like any packet (the driver must
//   not call the laser off before the board has run it).
// - A packet that is only "P" or "PN" toggles the pause at once, even when the
//   buffer is full: queued behind a paused executor, the resume could never run.
//   A move in progress freezes where it is and continues on resume.
// - Default-mode distances add up per axis and run as one straight rapid move
//   at 'N', 'S' or 'P'; compact-mode distances run as one move (along x, y or
//   the diagonal) at the next letter.
// - The board's own 'N'-turns-the-laser-off is modelled only where compact mode
//   is left ('N'), and a laser still on there is a violation: a driver ends a
//   burn with 'U'. A default-mode 'D' lights the laser in place (MeerK40t's
//   dwell); a rapid move with it lit is a violation.
// - "S0P" and a bare "SP" run the pending moves as "S1P" does, without touching
//   the rail; "SE" outside a jog and a lone 'E' do nothing (MeerK40t's
//   direction flip at 'E' is not modelled: our encoder restates directions).
// - A raster code's 'G' step moves the minor axis when the major axis letter
//   reverses in compact mode; a second 'G' group (unidirectional) is read and ignored.
// - A packet accepted while full() is kept but is a violation (the host must
//   wait for 206), as are bytes outside the language, digits left over before
//   a letter, unreadable speed codes, the head leaving the bed, and 'F'
//   padding inside compact mode (not followed by "NSE").

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace rotafab::devices::sim {

// One move, in mils in board coordinates: x right, y toward the front, home (0,0) at the back left.
struct BoardSegment {
  long x0, y0, x1, y1;
  bool laser;
  double mmPerSecond;
  bool homing = false;  // the homing run to (0,0): its speed is the distance over Options::homeSeconds
};

enum class BoardMode { Default, Compact, Finished };

// LhymicroBoard::Options (outside the class, so that `= {}` can default a
// constructor argument: a nested struct's initialisers are not usable there).
struct LhymicroBoardOptions {
  long bedWidthMils = 12205, bedHeightMils = 8268;  // 310 x 210 mm
  double rapidMmPerSecond = 100;                    // default-mode moves and compact-mode jogs
  double homeSeconds = 0.5;                         // "IPP", wherever the head is
  size_t capacityPackets = 8;                       // the board's buffer (its real depth is unknown)
  bool abortAtOnce = true;                          // a lone "I" acts on arrival (see above)
};

class LhymicroBoard {
 public:
  using Options = LhymicroBoardOptions;

  explicit LhymicroBoard(Options options = {});

  // One accepted packet's 30 payload bytes. Packet boundaries matter: two 'P'
  // in one packet (IPP) home; a lone P / "PN" toggles pause.
  void accept(const std::array<uint8_t, 30>& payload);
  // capacityPackets packets waiting (status BUSY).
  [[nodiscard]] bool full() const;

  // Runs the queued commands for `seconds` of machine time (moves take their
  // time at their speed; home takes homeSeconds). Nothing runs while paused.
  void advance(double seconds);

  // Something queued or a move in progress.
  [[nodiscard]] bool busy() const;
  [[nodiscard]] bool paused() const { return paused_; }
  [[nodiscard]] BoardMode mode() const { return mode_; }
  // Lit now; during a move, as that move is (the letter that ended its distance, a 'U' say, is read already).
  [[nodiscard]] bool laser() const { return actions_.empty() ? laser_ : actions_.front().segment.laser; }
  [[nodiscard]] bool railLocked() const { return railLocked_; }
  // The head now, in mils (part way along a move in progress).
  [[nodiscard]] long x() const;
  [[nodiscard]] long y() const;

  // Every move executed, in order (laser on/off, speed); a move cut short by an abort ends where it stopped.
  [[nodiscard]] const std::vector<BoardSegment>& trace() const { return trace_; }
  // Rule breaks a test asserts never happen, as text ("laser on in default
  // mode", "head off the bed at (x, y)", "unknown byte 0x.. ", ...).
  [[nodiscard]] const std::vector<std::string>& violations() const { return violations_; }
  // Set when a job's FNSE or a home has finished executing with nothing left
  // queued; cleared by accept(). The USB side reports status 236 from it.
  [[nodiscard]] bool finished() const;
  // Packets read to their end (an abort or pause packet counts; dropped ones do not).
  [[nodiscard]] size_t packetsExecuted() const { return packetsExecuted_; }
  [[nodiscard]] size_t packetsDropped() const { return packetsDropped_; }
  [[nodiscard]] double seconds() const { return clock_; }  // machine time advanced so far

 private:
  // Something that takes time: a move (at a speed) or the homing run.
  struct Action {
    BoardSegment segment;
    double duration = 0, elapsed = 0;
  };
  // Where the digits that arrive go.
  enum class Digits { Distance, Speed, Raster, SMode };

  void interpret(uint8_t byte);
  // The steps of interpret(), in the order it takes them for a byte of the language.
  void breakOffLeaving(char c);  // forgets a begun "FNSE" / "@NSE" that `c` does not go on with
  void readDigit(char c);        // into the distance, speed code, raster step or S mode being read
  // The digits before a letter are complete: true when `c` was a speed code's
  // low-speed suffix 'C', which they take and which says nothing else.
  bool endDigits(char c);
  bool readDistanceLetter(char c);  // '|', 'a'..'z': true when `c` was one
  void runCommand(char c);          // a command letter, the distance before it flushed
  // The letters whose meaning depends on the mode and on the letters before them.
  void runN();
  void runS();
  void runE();
  void runP();
  void reset();
  void abort();
  void violation(std::string text);
  void flushDistance();
  void addDistance(long mils);
  void runDefaultMove();
  void move(long dx, long dy, bool rapid);
  void home();
  void finishSpeedCode(bool suffixC);
  void direction(char letter);
  void complete(const Action& action);
  void checkOnBed(long x, long y);
  [[nodiscard]] bool onlyPaddingLeft() const;
  [[nodiscard]] int peekInPacket() const;  // the next byte of the packet being read, or -1 at its end

  Options options_;
  std::deque<std::array<uint8_t, 30>> queue_;
  size_t readAt_ = 0;  // in queue_.front()
  std::deque<Action> actions_;
  std::vector<BoardSegment> trace_;
  std::vector<std::string> violations_;
  size_t packetsExecuted_ = 0, packetsDropped_ = 0;
  double clock_ = 0;

  // Machine state.
  BoardMode mode_ = BoardMode::Default;
  bool jogging_ = false;  // compact mode left for rapid moves by 'N', back at "SE"
  bool paused_ = false, laser_ = false, railLocked_ = false, finishedLatch_ = false;
  long x_ = 0, y_ = 0;                   // where the last completed action left the head
  int xDirection_ = 1, yDirection_ = 1;  // B / T, R / L
  char engaged_ = 'x';                   // 'x', 'y' or 'm' (both: M)
  char majorAxis_ = 'x';                 // the engaged axis at S1E (raster steps go along the other)
  double compactSpeed_ = 0;              // mm/s
  long rasterStep_ = 0;

  // Parser state.
  Digits digits_ = Digits::Distance;
  std::string digitText_;
  long pendingDistance_ = 0;
  bool smallJump_ = false;            // after '|': the next 'z' is 26
  long pendingX_ = 0, pendingY_ = 0;  // default mode: the rapid move 'N', 'S' or 'P' runs
  double codeSpeed_ = 0;              // mm/s of the last speed code read
  int rasterGroups_ = 0;              // 'G' groups since the last 'V'
  int sMode_ = -2;                    // after 'S': -1 no digit yet, else the digit; -2 no 'S'
  char leaving_ = 0;                  // 'F' or '@' begun
  int leavingStep_ = 0;               // 1 after F/@, 2 after N, 3 after S
};

}  // namespace rotafab::devices::sim
