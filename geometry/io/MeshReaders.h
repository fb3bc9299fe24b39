#pragma once
// Strict readers for the two formats whose headers state their counts. They
// keep the file's vertex numbering and report errors as "LINE: what" (ASCII) or
// "what" (binary); the caller prefixes the file name.

#include <string_view>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// OFF, COFF, NOFF, CNOFF, STOFF... (Princeton shape benchmark / CGAL / Geomview):
// '#' comments anywhere, counts on the header line or the next, extra values
// after a vertex's coordinates or a face's indices (colours) ignored.
PolygonMesh readOff(std::string_view text);

// PLY 1.0, ascii and binary (little or big endian): the `vertex` element's x, y,
// z and the `face` element's vertex_indices (or vertex_index) list; all other
// elements and properties are skipped.
PolygonMesh readPly(std::string_view bytes);

}  // namespace rotafab::geometry
