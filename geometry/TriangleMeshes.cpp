#include "geometry/TriangleMeshes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/Polygon2.h"

namespace rotafab::geometry {
namespace {

Eigen::Vector2d inPlane(const Point3& p, const Point3& u, const Point3& v) { return {p.dot(u), p.dot(v)}; }

using core::turn;

}  // namespace

std::vector<std::array<int, 3>> faceTriangles(const PolygonMesh& mesh, int face) {
  const std::vector<int>& corners = mesh.faces[face];
  const size_t n = corners.size();
  std::vector<std::array<int, 3>> triangles;
  if (n == 3) return {{corners[0], corners[1], corners[2]}};
  std::vector<Point3> polygon;
  for (int v : corners) polygon.push_back(mesh.positions[v]);
  const Point3 normal = newellNormal(polygon);
  // The plane's axes, so that the polygon turns counter-clockwise in it.
  const Point3 u = normal.unitOrthogonal();
  const Point3 v = normal.cross(u);
  std::vector<Eigen::Vector2d> flat;
  for (const Point3& p : polygon) flat.push_back(inPlane(p, u, v));
  std::vector<size_t> left(n);
  for (size_t i = 0; i < n; ++i) left[i] = i;
  while (left.size() > 3) {
    bool clipped = false;
    const size_t m = left.size();
    for (size_t i = 0; i < m && !clipped; ++i) {
      const size_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
      if (turn(flat[a], flat[b], flat[c]) <= 0) continue;  // a reflex or straight corner is no ear
      bool empty = true;
      for (size_t k : left) {
        if (k == a || k == b || k == c) continue;
        if (turn(flat[a], flat[b], flat[k]) >= 0 && turn(flat[b], flat[c], flat[k]) >= 0 &&
            turn(flat[c], flat[a], flat[k]) >= 0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      triangles.push_back({corners[a], corners[b], corners[c]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) break;
  }
  if (left.size() == 3) {
    triangles.push_back({corners[left[0]], corners[left[1]], corners[left[2]]});
  } else {
    // No ear: a fan over what is left, so that every corner is still used.
    for (size_t i = 1; i + 1 < left.size(); ++i) {
      triangles.push_back({corners[left[0]], corners[left[i]], corners[left[i + 1]]});
    }
  }
  return triangles;
}

}  // namespace rotafab::geometry

namespace rotafab::geometry::triangles {
namespace {

std::mutex& openMeshStreams() {
  static std::mutex streams;
  return streams;
}

}  // namespace

QuietOpenMesh::QuietOpenMesh() : lock_(openMeshStreams()) {
  omerr().disable();
  omlog().disable();
  omout().disable();
}

QuietOpenMesh::~QuietOpenMesh() {
  omerr().enable();
  omlog().enable();
  omout().enable();
}

bool toTriangleMesh(const PolygonMesh& mesh, TriMesh& tri, SourceNumbers& source) {
  tri.add_property(source.vertex);
  tri.add_property(source.face);
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(mesh.positions.size());
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    handles.push_back(tri.add_vertex(toOpenMesh(mesh.positions[v])));
    tri.property(source.vertex, handles.back()) = mesh.sourceVertexIndex(v);
  }
  // A polygon's triangles may not join two of its corners that an edge
  // joins already (a third face on that edge): then a fan from another
  // corner, whose diagonals are all new.
  const auto joined = [&](int a, int b) {
    return tri.find_halfedge(handles[a], handles[b]).is_valid() || tri.find_halfedge(handles[b], handles[a]).is_valid();
  };
  const auto addable = [&](const std::vector<std::array<int, 3>>& pieces, const std::vector<int>& corners) {
    const size_t n = corners.size();
    for (const auto& t : pieces) {
      for (int i = 0; i < 3; ++i) {
        const int a = t[i], b = t[(i + 1) % 3];
        const auto at = std::find(corners.begin(), corners.end(), a) - corners.begin();
        const bool side = corners[(at + 1) % n] == b || corners[(at + n - 1) % n] == b;
        if (!side && joined(a, b)) return false;
      }
    }
    return true;
  };
  bool split = false;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const std::vector<int>& corners = mesh.faces[f];
    auto pieces = faceTriangles(mesh, f);
    split = split || pieces.size() > 1;
    for (size_t first = 0; first < corners.size() && !addable(pieces, corners); ++first) {
      pieces.clear();
      for (size_t i = 1; i + 1 < corners.size(); ++i) {
        pieces.push_back(
            {corners[first], corners[(first + i) % corners.size()], corners[(first + i + 1) % corners.size()]});
      }
    }
    for (const auto& t : pieces) {
      const auto handle = tri.add_face(handles[t[0]], handles[t[1]], handles[t[2]]);
      if (!handle.is_valid()) {
        throw InvalidMeshError(
            fmt::format("face {}: its triangles would give an edge a third face, so the mesh cannot be remeshed",
                        mesh.sourceFaceIndex(f)));
      }
      tri.property(source.face, handle) = mesh.sourceFaceIndex(f);
    }
  }
  return split;
}

PolygonMesh fromTriangleMesh(TriMesh& tri, const SourceNumbers& source) {
  tri.garbage_collection();
  PolygonMesh mesh;
  mesh.positions.reserve(tri.n_vertices());
  for (const auto vertex : tri.vertices()) {
    mesh.positions.push_back(toPoint(tri.point(vertex)));
    mesh.sourceVertex.push_back(tri.property(source.vertex, vertex));
  }
  mesh.faces.reserve(tri.n_faces());
  for (const auto face : tri.faces()) {
    std::vector<int> corners;
    for (const auto vertex : tri.fv_range(face)) corners.push_back(vertex.idx());
    mesh.faces.push_back(std::move(corners));
    mesh.sourceFace.push_back(tri.property(source.face, face));
  }
  return mesh;
}

double dihedralDegrees(const TriMesh& tri, TriMesh::EdgeHandle edge) {
  if (tri.is_boundary(edge)) return 0;
  const auto a = tri.face_handle(tri.halfedge_handle(edge, 0)), b = tri.face_handle(tri.halfedge_handle(edge, 1));
  const TriMesh::Normal na = tri.calc_face_normal(a), nb = tri.calc_face_normal(b);
  const double cosine = std::clamp(OpenMesh::dot(na, nb), -1.0, 1.0);
  return std::acos(cosine) * 180 / std::numbers::pi;
}

}  // namespace rotafab::geometry::triangles
