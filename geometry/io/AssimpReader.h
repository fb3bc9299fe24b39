#pragma once
// Reading a mesh file with Assimp, as the mesh reader program
// (rotafab-read-mesh, geometry/io/MeshReaderHost.cpp) does it: only that program
// links Assimp, so that Assimp runs in a process of its own (MeshImport.h).

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// Assimp's own words on a file it could not read, for the importer to put in
// the file's terms (MeshFileChecks.h).
class AssimpFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The mesh of every instance in the scene (node transforms applied), polygons
// kept as they are. `path`, when given, is the file the bytes came from, so
// that Assimp can find the files it refers to (an OBJ's materials, a glTF's
// buffers). Throws InvalidMeshError with one line on a file it cannot read,
// and when the file states more faces than could be read.
PolygonMesh readWithAssimp(std::string_view bytes, const std::string& extension, const std::filesystem::path* path);

}  // namespace rotafab::geometry
