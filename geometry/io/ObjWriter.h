#pragma once
// Writes a polygon mesh as Wavefront OBJ (1-based `f` lines, polygons kept),
// with the shortest decimal that reads back to each coordinate exactly.

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// A named group of faces (`g NAME`), from face `firstFace` to the next group.
struct ObjGroup {
  int firstFace = 0;
  std::string name;
};

// `groups` in the order of their first faces; faces before the first are in none.
void writeObj(std::ostream& out, const PolygonMesh& mesh, std::string_view comment = {},
              const std::vector<ObjGroup>& groups = {});

}  // namespace rotafab::geometry
