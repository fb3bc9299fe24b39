#pragma once
// Writes a sheet as plain SVG 1.1 (no CSS, no scripts, no fonts), for laser
// programs and editors that import SVG: LightBurn, Inkscape, browsers.
//
// The document is the bed: width="32in" height="18in" and viewBox="0 0 32 18",
// so one user unit is one inch. SVG's y grows downwards, so a sheet point
// (x, y) is written as (x, H - y): the bed's bottom-left corner, the sheet's
// origin, is the viewBox's bottom-left corner. The geometry is exactly that of
// the EPS and DXF of the same sheet.
//
// One group per operation that has paths, <g id="cut" fill="none"
// stroke="#0000ff" stroke-width="0.001" ...>, an Inkscape layer named for
// the operation; the bed's outline (never cut) is a layer of its own,
// "bed (not cut)", locked, out of the cut layers' way. In each, a group per
// part: <g id="panel-17"> in the cut layer, "panel-17-score" and
// "panel-17-etch" in the others, so that a panel can be picked whole. The
// paths are <path d="M ... L ... [Z]"> (Z when the path is closed); the
// stroke is the profile's exact colour (LightBurn assigns layers by it) and a
// 0.001 in hairline. Layers come in the order of their operation's first
// path; within one, parts in the order of their first path, and each part's
// paths in the drawing's (cutting) order. Coordinates have 9 decimals (1e-9 in).
//
// The same inputs as the EPS writer are refused, with std::invalid_argument.

#include <ostream>
#include <string>
#include <string_view>

#include "core/LengthUnit.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

void writeSvg(const SheetDrawing& sheet, std::ostream& out);

// The same sheet for people to look at (a cutter would burn its wide lines):
// the material light, cuts 0.02 in wide in dark blue, scores dashed in red,
// labels dark brown; the title and the sheet's size in `shownIn` above. Classes, not ids, so that many can
// share one HTML page.
void writeSvgPreview(const SheetDrawing& sheet, std::ostream& out, core::LengthUnit shownIn = {});

// Character data for XML 1.0 (and HTML): markup characters escaped, control
// characters (not allowed in XML 1.0) and bytes that are not valid UTF-8
// replaced by '?'.
std::string xmlText(std::string_view text);

}  // namespace rotafab::jobs
