#pragma once
// Writes a sheet as an ASCII DXF of release 12 ($ACADVER AC1009), the dialect
// every CAD and laser program still reads (LibreCAD, QCAD, LightBurn,
// AutoCAD, ezdxf).
//
// Units are inches and coordinates are the sheet's own (origin at the bed's
// bottom-left, y up), with 9 decimals. R12 has no units variable ($INSUNITS
// came with AutoCAD 2000), so the file says it three ways: $MEASUREMENT 0
// (imperial; read by R14 and later, ignored by older readers), $EXTMIN/
// $EXTMAX and $LIMMIN/$LIMMAX spanning the bed in inches, and a 999 comment.
// Importers that ask for the unit should be told "inches".
//
// One layer per operation that has a colour in the drawing, named CUT, SCORE,
// ETCH and OUTLINE, each with the ACI colour nearest to the profile's colour
// (nearestAci below); entities take their layer's colour (BYLAYER), since R12
// has no true colour. An open two-point path is a LINE; every other path is a
// POLYLINE of VERTEXes ended by SEQEND, with flag 70 = 1 when it is closed (the
// first point is not repeated). Entities come in the drawing's cutting order.
//
// The same inputs as the EPS writer are refused, with std::invalid_argument.

#include <ostream>
#include <string>

#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

void writeDxf(const SheetDrawing& sheet, std::ostream& out);

// "CUT", "SCORE", "ETCH", "OUTLINE".
std::string dxfLayerName(Operation operation);

// The AutoCAD Color Index palette: 1-6 red, yellow, green, cyan, blue,
// magenta; 7 black or white (the foreground colour; given here as black,
// what it is on paper and in laser programs); 8 and 9 grays; 10-249 24 hues
// every 15 degrees, each in 5 shades, full and half saturated; 250-255 grays.
// Entries 10-255 are computed from that scheme and are within 1 of the
// published table, which is close enough to choose a nearest colour.
Rgb aciColour(int index);  // index in 1..255

// The ACI index whose colour is nearest to `rgb` (Euclidean in RGB; ties to
// the lowest index, so the pure colours get 1-7), where 7 counts as black and
// as white.
int nearestAci(Rgb rgb);

}  // namespace rotafab::jobs
