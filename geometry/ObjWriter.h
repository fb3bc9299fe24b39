#pragma once
// Writes a polygon mesh as Wavefront OBJ (1-based `f` lines, polygons kept),
// with the shortest decimal that reads back to each coordinate exactly.

#include <ostream>
#include <string_view>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

void writeObj(std::ostream& out, const PolygonMesh& mesh, std::string_view comment = {});

}  // namespace rotafab::geometry
