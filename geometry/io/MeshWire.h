#pragma once
// A mesh as bytes, to come back from the mesh reader program
// (geometry/io/MeshReaderHost.cpp) through a pipe: counts, the coordinates as
// one block, then each face's size and corners. Both ends are this machine's
// one build, so the bytes are in its own order and layout.

#include <string>
#include <string_view>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

std::string serializeMesh(const PolygonMesh& mesh);

// Throws InvalidMeshError when the bytes are cut short or are no mesh (an
// index out of range, a coordinate not finite, bytes left over).
PolygonMesh deserializeMesh(std::string_view bytes);

}  // namespace rotafab::geometry
