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

#include <vector>

#include "devices/ruida/RuidaCodec.h"
#include "toolpath/Toolpath.h"

namespace rotafab::devices::ruida {

struct RuidaJobOptions {
  bool airAssist = true;  // a CO2 cut wants it: the lens kept clean, no flame
};

// The job's logical bytes, ending with the end of file (0xD7).
Bytes jobStream(const jobs::Toolpath& toolpath, const RuidaJobOptions& options = {});

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
