#pragma once
// Writes a sheet as Encapsulated PostScript (Adobe DSC 3.0, EPSF 3.0, language
// level 1), the format of the dissertation's workshop cutter: its print
// driver reads each stroke's colour to choose the operation (fig. 65), so
// every path is a stroked vector in its operation's exact profile colour with
// a 0.001 in (0.072 pt) hairline width, and nothing else is drawn: no fonts
// (etched text arrives as polylines), no fills, no images.
//
// The page is the bed: %%BoundingBox 0 0 W H in points (a 32 x 18 in bed gives
// 0 0 2304 1296), origin at the bed's bottom-left corner, y up, as in the
// SheetDrawing. Coordinates are written in points with 4 decimals (1e-4 pt,
// about 1.4e-6 in); colours as r/255 with 6 decimals, which reads back to the
// same 8-bit value. Paths come in the drawing's (cutting) order. Output is
// deterministic (no creation date) and 7-bit clean, lines under 255 bytes.
//
// A path with fewer than 2 points, a non-finite or off-bed coordinate, or an
// operation without a colour in the drawing is refused with
// std::invalid_argument before anything is written.

#include <ostream>

#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

void writeEps(const SheetDrawing& sheet, std::ostream& out);

}  // namespace rotafab::jobs
