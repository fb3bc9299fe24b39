#pragma once
// Progress of long work, as data: which phase and step, how far of how
// much, and for nesting the layout reached. The command line turns it into
// its lines and bars, the daemon into events for its clients; the work never
// writes a sentence for people itself.

#include <cstddef>
#include <functional>
#include <string>

namespace rotafab::core {

struct Progress {
  // The phases of a job, in order: "import", "geometry", "nesting", "writing".
  std::string phase;
  // What within the phase, for example "band decomposition", "fastener
  // holes", "labels" (geometry); "first layout", "improving", "compacting"
  // (nesting), and "searching" (nesting: still at it, with nothing better
  // yet); empty for the start of the phase.
  std::string step;
  size_t done = 0;   // units of the step done (faces, bands, panels, parts, sheets)
  size_t total = 0;  // of how many; 0 when the step is not counted
  // Nesting: the best layout so far, its sheets and the length of the last
  // one (in a strip: the strip's length), inches.
  int sheets = 0;
  double length = 0;
  // Nesting: seconds since it began, of its budget (0: none given).
  double elapsed = 0, budget = 0;
};

using ProgressSink = std::function<void(const Progress&)>;

}  // namespace rotafab::core
