#pragma once
// A sheet's toolpath as a Ruida job, the stream RDWorks and LightBurn send
// and save as .rd (before swizzling), and back: the header with the job's
// bounds and a layer for each power and speed, the body of moves and cuts
// (absolute for the first and for steps beyond the 14-bit relative reach,
// relative otherwise), and the trailer with its file sum. The layout is the
// one LightBurn writes, as the public descriptions decode it.
//
// Coordinates: the sheet's (inches, origin at the bed's bottom-left, y up)
// become the controller's micrometres from the bed's top-left corner, y
// down, where a Ruida machine's origin is.

#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "devices/ruida/RuidaCodec.h"
#include "toolpath/Toolpath.h"

namespace rotafab::devices::ruida {

struct RuidaJobOptions {
  bool airAssist = true;  // a CO2 cut wants it: the lens kept clean, no flame
};

// The job's logical bytes, ending with the end of file (0xD7).
Bytes jobStream(const jobs::Toolpath& toolpath, const RuidaJobOptions& options = {});

// A job of moves alone (laser off) around the box of the toolpath's
// strokes: the sheet's frame.
Bytes frameStream(const jobs::Toolpath& toolpath);

// A controller's reading of a job, one whole command at a time (as it
// arrives): each move or cut as a step, in the controller's micrometres,
// with the power and speed it is made at.
struct JobStep {
  long fromX = 0, fromY = 0, toX = 0, toY = 0;
  bool lit = false;
  double power = 0;  // 0..1, for a cut
  double speed = 0;  // micrometres a second (the layer's; a move goes at the machine's own)
};
class JobReader {
 public:
  // Throws std::invalid_argument naming the command when it is cut short.
  std::optional<JobStep> read(const Bytes& command);
  [[nodiscard]] bool ended() const { return ended_; }        // the end of file (0xD7) was read
  [[nodiscard]] bool sumHolds() const { return sumHolds_; }  // its file sum (E5 05) matches the bytes before it

 private:
  std::array<std::pair<double, double>, 256> layers_{};  // power, speed
  double power_ = 0, speed_ = 0;
  long x_ = 0, y_ = 0;
  long sum_ = 0;
  bool ended_ = false, sumHolds_ = false;
};

// What a controller would do with a stream: each run of cuts as a stroke
// with the laser lit at its layer's power and speed, in the sheet's
// coordinates (the inverse of jobStream's mapping, for a bed `height`
// inches tall). Throws std::invalid_argument naming the first command it
// cannot read.
struct DecodedStroke {
  double power = 0;  // 0..1
  double speed = 0;  // in/s
  std::vector<jobs::Point2> points;
};
struct DecodedJob {
  std::vector<DecodedStroke> strokes;
  bool ended = false;     // the end of file (0xD7) was read
  bool sumHolds = false;  // its file sum (E5 05) matches the bytes before it
};
DecodedJob decodeJob(const Bytes& stream, double height);

}  // namespace rotafab::devices::ruida
