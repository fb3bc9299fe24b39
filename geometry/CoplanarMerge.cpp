#include "geometry/CoplanarMerge.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "core/Polygon2.h"
#include "geometry/BandDecomposition.h"

namespace rotafab::geometry {
namespace {

long long edgeKey(int from, int to) { return (static_cast<long long>(from) << 32) | static_cast<unsigned>(to); }

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

// A vertex on a straight side between two merged faces, that had more
// faces before and has only those two now, goes from both: the band
// decomposition gives a face's corner at a vertex of two faces a place that
// does not depend on the vertex, so two such vertices in a row would put one
// point twice into a panel (V.1-V.2, a band of zero length). It stays where
// taking it out would leave a face of two corners, add an edge the two faces
// already share elsewhere, or bend the side by more than the angle.
int straightenSides(const PolygonMesh& before, std::vector<std::vector<int>>& faces, double degrees) {
  const size_t vertices = before.positions.size();
  std::vector<int> facesBefore(vertices, 0);
  for (const auto& face : before.faces)
    for (int v : face) ++facesBefore[v];
  std::vector<std::vector<int>> facesOf(vertices);
  std::unordered_set<long long> edges;
  auto key = [](int a, int b) { return edgeKey(std::min(a, b), std::max(a, b)); };
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    for (size_t i = 0; i < faces[f].size(); ++i) {
      facesOf[faces[f][i]].push_back(f);
      edges.insert(key(faces[f][i], faces[f][(i + 1) % faces[f].size()]));
    }
  }
  const double cosLimit = std::cos(degrees * std::numbers::pi / 180.0);
  int straightened = 0;
  for (int v = 0; v < static_cast<int>(vertices); ++v) {
    if (facesOf[v].size() != 2 || facesBefore[v] <= 2) continue;
    auto& a = faces[facesOf[v][0]];
    auto& b = faces[facesOf[v][1]];
    if (a.size() <= 3 || b.size() <= 3) continue;
    const size_t i = std::find(a.begin(), a.end(), v) - a.begin(), j = std::find(b.begin(), b.end(), v) - b.begin();
    const int previous = a[(i + a.size() - 1) % a.size()], next = a[(i + 1) % a.size()];
    // Inside the surface: b runs the same two sides the other way.
    if (b[(j + 1) % b.size()] != previous || b[(j + b.size() - 1) % b.size()] != next) continue;
    if (edges.count(key(previous, next))) continue;
    const Point3 in = before.positions[v] - before.positions[previous],
                 out = before.positions[next] - before.positions[v];
    if (in.dot(out) < cosLimit * in.norm() * out.norm()) continue;
    a.erase(a.begin() + static_cast<long>(i));
    b.erase(b.begin() + static_cast<long>(j));
    edges.erase(key(previous, v));
    edges.erase(key(v, next));
    edges.insert(key(previous, next));
    facesOf[v].clear();
    ++straightened;
  }
  return straightened;
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
    std::vector<Point3> polygon;
    for (int v : mesh.faces[f]) polygon.push_back(mesh.positions[v]);
    normals[f] = newellNormal(polygon);
    const auto& corners = mesh.faces[f];
    for (size_t i = 0; i < corners.size(); ++i) faceOfEdge[edgeKey(corners[i], corners[(i + 1) % corners.size()])] = f;
  }

  std::vector<int> regionOf(mesh.faces.size(), -1);
  std::unordered_map<int, std::vector<int>> outlineOfSeed;  // the merged regions
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
      // Not one simple face: each face stays as it is (a region of its own,
      // so that no later region counts it as inside).
      for (int f : region) regionOf[f] = mesh.faceCount() + f;
      continue;
    }
    ++result.regions;
    outlineOfSeed.emplace(seed, std::move(outline));
  }
  // In the order of the faces, each merged face where its seed was.
  std::vector<std::vector<int>> faces;
  std::vector<int> sources;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (const auto merged = outlineOfSeed.find(f); merged != outlineOfSeed.end()) {
      faces.push_back(std::move(merged->second));
    } else if (regionOf[f] < mesh.faceCount()) {
      result.mergedInto[mesh.sourceFaceIndex(f)] = mesh.sourceFaceIndex(regionOf[f]);
      continue;  // inside a merged face
    } else {
      faces.push_back(mesh.faces[f]);
    }
    sources.push_back(mesh.sourceFaceIndex(f));
  }

  if (result.regions > 0) result.straightened = straightenSides(mesh, faces, degrees);

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
