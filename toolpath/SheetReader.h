#pragma once
// Reads a sheet that `make` wrote back into a SheetDrawing, for `rotafab run`:
// the SVG, whose groups are named by operation ("cut", "score", "etch",
// "outline") and whose paths are in cutting order. Only what our SVG writer
// writes is read (M, L and Z in absolute coordinates, y down from the top of
// the bed); anything else is refused, naming the file and the line.

#include <filesystem>

#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

// Throws std::invalid_argument "FILE:LINE: what is wrong".
SheetDrawing readSheetSvg(const std::filesystem::path& file);

}  // namespace rotafab::jobs
