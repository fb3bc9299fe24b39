#include "geometry/CoplanarMerge.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <queue>
#include <unordered_map>
#include <vector>

#include "core/Polygon2.h"

namespace rotafab::geometry {
namespace {

long long edgeKey(int from, int to) { return (static_cast<long long>(from) << 32) | static_cast<unsigned>(to); }

// The unit normal of a face (Newell's method: right for any planar polygon
// and a fair average for a warped one).
Point3 faceNormal(const PolygonMesh& mesh, int face) {
  Point3 normal = Point3::Zero();
  const auto& corners = mesh.faces[face];
  for (size_t i = 0; i < corners.size(); ++i) {
    const Point3& a = mesh.positions[corners[i]];
    const Point3& b = mesh.positions[corners[(i + 1) % corners.size()]];
    normal += a.cross(b);
  }
  const double length = normal.norm();
  return length > 0 ? Point3(normal / length) : Point3::Zero();
}

// The outline of a region of faces (oriented alike) as one loop of
// vertices, or nothing when it is not a disc with one simple outline.
std::vector<int> regionOutline(const PolygonMesh& mesh, const std::vector<int>& region,
                               const std::vector<int>& regionOf, int id,
                               const std::unordered_map<long long, int>& faceOfEdge, const Point3& normal) {
  // The sides whose other side is not in the region, by their first vertex.
  std::unordered_map<int, int> nextOf;
  size_t sides = 0;
  long long edgesInside = 0;  // each interior edge counted from both sides
  std::unordered_map<int, char> vertices;
  for (int f : region) {
    const auto& corners = mesh.faces[f];
    for (size_t i = 0; i < corners.size(); ++i) {
      const int from = corners[i], to = corners[(i + 1) % corners.size()];
      vertices[from] = 1;
      const auto across = faceOfEdge.find(edgeKey(to, from));
      if (across != faceOfEdge.end() && regionOf[across->second] == id) {
        ++edgesInside;
        continue;
      }
      if (!nextOf.emplace(from, to).second) return {};  // two outline sides leave one vertex: it pinches
      ++sides;
    }
  }
  // A disc: V - E + F = 1, E counting the outline once and the inside once.
  const long long euler = static_cast<long long>(vertices.size()) - (static_cast<long long>(sides) + edgesInside / 2) +
                          static_cast<long long>(region.size());
  if (euler != 1 || sides < 3) return {};
  // From the seed's first corner on the outline: the same face, run after run.
  int start = nextOf.begin()->first;
  for (int corner : mesh.faces[region.front()]) {
    if (nextOf.count(corner)) {
      start = corner;
      break;
    }
  }
  std::vector<int> outline{start};
  while (outline.size() <= sides) {
    const auto next = nextOf.find(outline.back());
    if (next == nextOf.end()) return {};
    if (next->second == outline.front()) break;
    outline.push_back(next->second);
  }
  if (outline.size() != sides) return {};  // more than one loop: a hole
  // Simple in the plane, and turning the way the faces do.
  const Point3 u = normal.unitOrthogonal(), v = normal.cross(u);
  core::Polygon2 flat;
  for (int vertex : outline) flat.emplace_back(mesh.positions[vertex].dot(u), mesh.positions[vertex].dot(v));
  if (!(core::signedArea(flat) > 0) || core::crossesItself(flat)) return {};
  return outline;
}

}  // namespace

CoplanarMerge mergeCoplanarFaces(PolygonMesh& mesh, double degrees) {
  CoplanarMerge result;
  result.facesBefore = mesh.faceCount();
  const double cosLimit = std::cos(degrees * std::numbers::pi / 180.0);
  std::unordered_map<long long, int> faceOfEdge;
  faceOfEdge.reserve(mesh.faces.size() * 4);
  std::vector<Point3> normals(mesh.faces.size());
  for (int f = 0; f < mesh.faceCount(); ++f) {
    normals[f] = faceNormal(mesh, f);
    const auto& corners = mesh.faces[f];
    for (size_t i = 0; i < corners.size(); ++i) faceOfEdge[edgeKey(corners[i], corners[(i + 1) % corners.size()])] = f;
  }

  std::vector<int> regionOf(mesh.faces.size(), -1);
  std::vector<std::vector<int>> faces;
  std::vector<int> sources;
  for (int seed = 0; seed < mesh.faceCount(); ++seed) {
    if (regionOf[seed] >= 0) continue;
    const int id = seed;  // a region is named by its seed
    std::vector<int> region{seed};
    regionOf[seed] = id;
    for (size_t next = 0; next < region.size(); ++next) {
      const auto& corners = mesh.faces[region[next]];
      for (size_t i = 0; i < corners.size(); ++i) {
        const auto across = faceOfEdge.find(edgeKey(corners[(i + 1) % corners.size()], corners[i]));
        if (across == faceOfEdge.end()) continue;
        const int g = across->second;
        if (regionOf[g] >= 0 || normals[g].dot(normals[seed]) < cosLimit) continue;
        regionOf[g] = id;
        region.push_back(g);
      }
    }
    std::vector<int> outline;
    if (region.size() > 1) outline = regionOutline(mesh, region, regionOf, id, faceOfEdge, normals[seed]);
    if (outline.empty()) {
      // Not one simple face: each face stays as it is (and leaves the region,
      // so that no later region counts it as inside).
      for (int f : region) {
        regionOf[f] = mesh.faceCount() + f;
        faces.push_back(mesh.faces[f]);
        sources.push_back(mesh.sourceFaceIndex(f));
      }
      continue;
    }
    ++result.regions;
    faces.push_back(std::move(outline));
    sources.push_back(mesh.sourceFaceIndex(seed));
  }

  // Vertices no face refers to any more (inside a merged region) go; the
  // others keep their order and their source index. No welding: a vertex
  // that a repair split stays split.
  std::vector<int> newIndex(mesh.positions.size(), -1);
  for (const auto& face : faces)
    for (int v : face) newIndex[v] = 0;
  std::vector<Point3> positions;
  std::vector<int> vertexSources;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (newIndex[v] < 0) continue;
    newIndex[v] = static_cast<int>(positions.size());
    positions.push_back(mesh.positions[v]);
    vertexSources.push_back(mesh.sourceVertexIndex(v));
  }
  for (auto& face : faces)
    for (int& v : face) v = newIndex[v];
  mesh.positions = std::move(positions);
  mesh.sourceVertex = std::move(vertexSources);
  mesh.faces = std::move(faces);
  mesh.sourceFace = std::move(sources);
  result.facesAfter = mesh.faceCount();
  return result;
}

}  // namespace rotafab::geometry
