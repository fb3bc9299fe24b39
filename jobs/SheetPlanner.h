#pragma once
// The job planner: from parts to laser-ready sheets. Kerf
// compensation, true-shape nesting on the machine's bed within its margins,
// the cutting order on each sheet (etch, then score, then inner cuts, then
// outer cuts: a part is cut free last, so nothing moves while it is worked
// on), the profile's colour for each operation, and the files.

#include <filesystem>
#include <string>
#include <vector>

#include "core/LengthUnit.h"
#include "core/WorkContext.h"
#include "geometry/Structure.h"
#include "jobs/Nesting.h"
#include "jobs/Part.h"
#include "profiles/Profiles.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

struct PlanOptions {
  double kerf = 0.0;                        // from the material profile
  double spacing = -1.0;                    // between two cut paths; negative: 1/16 in of material plus the kerf
  double seconds = kDefaultNestingSeconds;  // the whole nesting's budget (NestingOptions::seconds)
  int evaluations = 0;                      // NestingOptions::evaluations
  OrderMode order = OrderMode::Kits;
  int window = 8;
  unsigned seed = 1;
  bool rows = false;  // rowLayout() instead of nest(): seconds for any size, more sheets
  std::string title;  // "bunny (band)"; the sheet number is appended
};

struct PlannedPart {
  int part = 0;         // index into the parts
  int sheet = 1;        // 1-based
  double x = 0, y = 0;  // part frame -> sheet: rotate by `rotation` degrees about the origin, then translate
  double rotation = 0;
  int cuttingIndex = 0;  // 0-based position in the cutting order over all sheets
  int moved = 0;         // cuttingIndex - assembly order: how far the layout moved the part
};

// The files written for each sheet (besides its preview for people).
struct SheetFormats {
  bool eps = true, svg = true, dxf = false;
};
// EPS and SVG (docs/CONTRACT.md, "make"), and what the machine profile's `formats` adds.
SheetFormats defaultFormats(const profiles::MachineProfile& machine);
// "eps,svg,dxf" or any of them; throws std::invalid_argument saying what is wrong.
SheetFormats formatsOf(const std::string& list);

struct SheetPlan {
  std::vector<SheetDrawing> sheets;
  std::vector<PlannedPart> parts;  // in cutting order
  double partArea = 0;             // of the design outlines, square inches
  double utilization = 0;          // part area / usable area of all sheets
  // Why the nesting's search stopped (NestingResult::stopped).
  std::string stopped;
  // What the nesting had no time for (NestingResult::inRows, inRowsNote()), else empty.
  std::string inRowsNote;
};

// Throws std::invalid_argument naming the part that cannot be planned (larger
// than the usable bed, a hole narrower than the kerf), core::Cancelled when
// the context is cancelled. Progress: nest()'s.
SheetPlan planSheets(const std::vector<Part>& parts, const profiles::MachineProfile& machine,
                     const PlanOptions& options, const core::WorkContext& context);

// How many times larger every part could be and still fit the machine's
// usable bed in one of its allowed rotations, its cut kerf/2 outside the
// design (>= 1: all fit as they are). A part's box grows with it.
double roomOnTheBed(const std::vector<Part>& parts, const profiles::MachineProfile& machine, double kerf);

// The point of a part's frame on its sheet.
Point2 onSheet(const PlannedPart& placement, const Point2& local);

// A part's name as an SVG id: "panel 17" -> "panel-17".
std::string partId(const std::string& name);

// The preview of a sheet for people: "sheet-001.preview.svg".
std::string previewFile(int sheet);

// Writes sheet-001.eps, .svg and .dxf, ... (those `formats` asks for) into `folder` (each atomically),
// and each sheet's preview (previewFile()), the sheets shared out on the
// context's executor; returns the file names of each sheet's cut files
// (not the preview, whose caption gives the sheet's size in `shownIn`), in
// order. Throws core::Cancelled.
std::vector<std::vector<std::string>> writeSheets(const SheetPlan& plan, const SheetFormats& formats,
                                                  const std::filesystem::path& folder, const core::WorkContext& context,
                                                  core::LengthUnit shownIn = {});

// The panels as parts for the planner: outline, fastener holes (circles),
// labels to etch, folds to score. The parts' order runs over the panels in
// assembly order, each panel's pieces (geometry::PanelPiece) right after it
// as parts of their own.
std::vector<Part> structureParts(const geometry::Structure& structure);

// For each of structureParts()'s parts, in its order: its panel (index) and
// its piece (index, -1 for the panel itself).
std::vector<std::pair<int, int>> partOwners(const geometry::Structure& structure);

}  // namespace rotafab::jobs
