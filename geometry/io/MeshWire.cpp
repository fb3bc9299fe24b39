#include "geometry/io/MeshWire.h"

#include <cstdint>
#include <cstring>

namespace rotafab::geometry {

static_assert(sizeof(Point3) == 3 * sizeof(double), "Point3 is three packed doubles");

std::string serializeMesh(const PolygonMesh& mesh) {
  size_t corners = 0;
  for (const auto& face : mesh.faces) corners += face.size();
  std::string out;
  out.reserve(16 + mesh.positions.size() * sizeof(Point3) + mesh.faces.size() * 4 + corners * sizeof(int));
  auto put = [&](const void* data, size_t size) { out.append(static_cast<const char*>(data), size); };
  const uint64_t vertices = mesh.positions.size(), faces = mesh.faces.size();
  put(&vertices, sizeof vertices);
  put(mesh.positions.data(), mesh.positions.size() * sizeof(Point3));
  put(&faces, sizeof faces);
  for (const auto& face : mesh.faces) {
    const uint32_t size = static_cast<uint32_t>(face.size());
    put(&size, sizeof size);
    put(face.data(), face.size() * sizeof(int));
  }
  return out;
}

PolygonMesh deserializeMesh(std::string_view bytes) {
  size_t at = 0;
  auto take = [&](void* into, uint64_t size) {
    if (size > bytes.size() - at) throw InvalidMeshError("the reader's result was cut short");
    std::memcpy(into, bytes.data() + at, size);
    at += size;
  };
  PolygonMesh mesh;
  uint64_t vertices = 0, faces = 0;
  take(&vertices, sizeof vertices);
  if (vertices > bytes.size() / sizeof(Point3)) throw InvalidMeshError("the reader's result was cut short");
  mesh.positions.resize(vertices);
  take(mesh.positions.data(), vertices * sizeof(Point3));
  take(&faces, sizeof faces);
  if (faces > bytes.size() / sizeof(uint32_t)) throw InvalidMeshError("the reader's result was cut short");
  mesh.faces.resize(faces);
  for (auto& face : mesh.faces) {
    uint32_t size = 0;
    take(&size, sizeof size);
    if (size > bytes.size() / sizeof(int)) throw InvalidMeshError("the reader's result was cut short");
    face.resize(size);
    take(face.data(), size * sizeof(int));
    // What the importer goes on with must hold, whatever the reader's state
    // was when it wrote (its heap may have been spoilt by a hostile file).
    for (int v : face) {
      if (v < 0 || static_cast<uint64_t>(v) >= vertices) throw InvalidMeshError("the reader's result is corrupt");
    }
  }
  if (at != bytes.size()) throw InvalidMeshError("the reader's result is corrupt");
  for (const Point3& p : mesh.positions) {
    if (!p.allFinite()) throw InvalidMeshError("the reader's result is corrupt");
  }
  return mesh;
}

}  // namespace rotafab::geometry
