// libFuzzer target: whatever the bytes, import and analysis end in a mesh or an
// InvalidMeshError, never a crash, a hang, or another exception; a usable mesh
// goes on through the rotation system, face tracing, dual and corner cutting.
// The first byte picks the reader: off, ply, obj, stl, glb, gltf, 3mf, dae.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "geometry/CornerCutting.h"
#include "geometry/DualMesh.h"
#include "geometry/FaceTracing.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/io/MeshImport.h"

namespace geo = rotafab::geometry;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static constexpr std::string_view kExtensions[] = {"off", "ply", "obj", "stl", "glb", "gltf", "3mf", "dae"};
  const std::string_view extension = kExtensions[data[0] % 8];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    geo::ImportedMesh imported = geo::importMeshFromMemory(bytes, extension, "fuzz");
    const geo::MeshAnalysis analysis = geo::analyzeMesh(imported.mesh);
    if (!analysis.usable() || imported.mesh.faceCount() > 5000) return 0;
    geo::RotationSystem rs = geo::RotationSystem::fromMesh(imported.mesh);
    geo::traceAllFaces(rs);
    rs.twistAll(1);
    geo::traceAllFaces(rs);
    geo::dualMesh(imported.mesh, rs);
    geo::cornerCut(imported.mesh, rs);
  } catch (const geo::InvalidMeshError&) {
  }
  return 0;
}
