#pragma once
// The command line's rendering of structured progress (core/Progress.h) as
// lines on standard error: "make: band decomposition of 32 faces",
// "nest: first layout: 120 of 600 parts placed, 3 sheets", ... A first
// layout's count is shown every 5 s at most.

#include <chrono>
#include <string>

#include "core/LengthUnit.h"
#include "core/Progress.h"

namespace rotafab::cli {

struct ProgressLineOptions {
  std::string prefix;         // "make: " or "nest: "
  std::string nestingPrefix;  // before nesting steps: "nesting: " for make
  bool strip = false;         // compacting a strip (its length), not beds
  std::string bed;            // "32 x 18 in", for the start of nesting
  bool rows = false;          // the layout is rows, not nesting
  std::string folder;         // where the sheets are written
  core::LengthUnit unit;      // of the lengths said
};

class ProgressLines {
 public:
  explicit ProgressLines(ProgressLineOptions options) : options_(std::move(options)) {}
  void operator()(const core::Progress& progress);

 private:
  ProgressLineOptions options_;
  std::chrono::steady_clock::time_point nextCount_{};
};

}  // namespace rotafab::cli
