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
// One group per operation that has paths, <g id="cut" stroke="#0000ff"
// fill="none" stroke-width="0.001">, holding that operation's paths as
// <path d="M ... L ... [Z]"> (Z when the path is closed); the stroke is the
// profile's exact colour (LightBurn assigns layers by it) and a 0.001 in
// hairline. Groups come in the order of their operation's first path, and each
// keeps the drawing's (cutting) order. Coordinates have 9 decimals (1e-9 in).
//
// The same inputs as the EPS writer are refused, with std::invalid_argument.

#include <ostream>
#include <string>
#include <string_view>

#include "jobs/SheetDrawing.h"

namespace rotafab::jobs {

void writeSvg(const SheetDrawing& sheet, std::ostream& out);

// Character data for XML 1.0 (and HTML): markup characters escaped, control
// characters (not allowed in XML 1.0) and bytes that are not valid UTF-8
// replaced by '?'.
std::string xmlText(std::string_view text);

}  // namespace rotafab::jobs
