#pragma once
// The mesh as OpenMesh's triangle mesh, for the steps that edit a surface by
// edge collapses, splits and flips (Simplification.cpp, Remeshing.cpp):
// double precision, OpenMesh's status flags (deleted, locked, feature), and
// each vertex's and face's number in the file carried as properties.

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <array>
#include <mutex>
#include <vector>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// The triangles of one face (three vertex indices each, in the face's
// winding): ear clipping in the face's plane (Newell's normal), so that a
// simple polygon, convex or not, is covered exactly; a fan from the first
// corner where no ear is found (a polygon that crosses itself).
std::vector<std::array<int, 3>> faceTriangles(const PolygonMesh& mesh, int face);

}  // namespace rotafab::geometry

namespace rotafab::geometry::triangles {

struct DoubleTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

// A vertex's and a face's number in the file (PolygonMesh::sourceVertexIndex,
// sourceFaceIndex), kept through the edits: a split's new vertex has none (-1).
struct SourceNumbers {
  OpenMesh::VPropHandleT<int> vertex;
  OpenMesh::FPropHandleT<int> face;
};

// OpenMesh's streams off while it lives: a library's message is not ours to
// print. The streams are the process's, so one edit runs at a time (a daemon
// may plan two jobs at once); not reentrant.
class QuietOpenMesh {
 public:
  QuietOpenMesh();
  ~QuietOpenMesh();
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
};

// `mesh` as triangles (each polygon split by faceTriangles(), or by a fan
// where those would join two corners an edge joins already), with its
// source numbers in `source` (added to `tri`). Returns whether a polygon was
// split. Throws InvalidMeshError naming the face whose triangle OpenMesh
// refuses (an edge with a third face). Call within a QuietOpenMesh.
bool toTriangleMesh(const PolygonMesh& mesh, TriMesh& tri, SourceNumbers& source);

// The triangles back as a PolygonMesh, with their source numbers; `tri`
// garbage-collected first.
PolygonMesh fromTriangleMesh(TriMesh& tri, const SourceNumbers& source);

// The angle between the normals of an edge's two faces (0: flat), in degrees.
double dihedralDegrees(const TriMesh& tri, TriMesh::EdgeHandle edge);

inline Point3 toPoint(const TriMesh::Point& p) { return {p[0], p[1], p[2]}; }
inline TriMesh::Point toOpenMesh(const Point3& p) { return {p.x(), p.y(), p.z()}; }

}  // namespace rotafab::geometry::triangles
