#pragma once
// Mesh import: OFF and PLY through our own strict readers (Assimp 5.2 was
// measured to drop OFF faces after comment lines, to clamp out-of-range OFF
// indices and to invent faces for truncated PLY/OFF files), every other format
// (OBJ, STL, glTF, 3MF, Collada, FBX, ...) through Assimp, with the face count
// checked against the file where it can be counted cheaply.
//
// All meshes of a scene are merged (node transforms applied), vertices at
// identical positions are welded, polygons are kept as they are. Faces with
// fewer than 3 distinct vertices and unreferenced vertices are dropped with one
// warning. Throws InvalidMeshError("FILE: what is wrong") on unreadable input:
// missing/empty/truncated file, unknown format, out-of-range index, non-finite
// coordinate, no faces at all.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/Cancellation.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct ImportedMesh {
  PolygonMesh mesh;
  std::vector<std::string> warnings;  // one line each, without the file name
};

// A cancel stops the import within 100 ms (core::Cancelled).
ImportedMesh importMesh(const std::filesystem::path& path, const core::Cancellation* cancellation = nullptr);

// The same from bytes in memory; `extension` picks the reader ("off", "obj",
// ...) and `displayName` prefixes messages. Used by the fuzz target.
ImportedMesh importMeshFromMemory(std::string_view bytes, std::string_view extension, std::string_view displayName);

struct CleaningReport {
  int weldedVertices = 0;   // vertices merged into an earlier one at the same position
  int droppedFaces = 0;     // faces with fewer than 3 distinct vertices
  int droppedVertices = 0;  // vertices no face refers to
};

// Welds identical positions, removes consecutive repeated corners, drops
// degenerate faces and unreferenced vertices; keeps the order of what stays.
CleaningReport cleanMesh(PolygonMesh& mesh);

}  // namespace rotafab::geometry
