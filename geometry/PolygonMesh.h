#pragma once
// A polygon mesh as imported: positions and faces given as cyclic lists of
// vertex indices. Faces keep their polygon size (no triangulation). After
// analyzeMesh() orients it, every face runs counter-clockwise seen from the
// outside of the surface.

#include <Eigen/Dense>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace rotafab::geometry {

using Point3 = Eigen::Vector3d;

struct PolygonMesh {
  std::vector<Point3> positions;
  std::vector<std::vector<int>> faces;
  // Where each vertex and face was read from (its index in the file for OFF
  // and PLY, in the importer's order otherwise), so that messages name what a
  // user can find; empty when the mesh was not cleaned from a file.
  std::vector<int> sourceVertex;
  std::vector<int> sourceFace;

  [[nodiscard]] int vertexCount() const { return static_cast<int>(positions.size()); }
  [[nodiscard]] int faceCount() const { return static_cast<int>(faces.size()); }
  [[nodiscard]] int sourceVertexIndex(int v) const { return sourceVertex.empty() ? v : sourceVertex[v]; }
  [[nodiscard]] int sourceFaceIndex(int f) const { return sourceFace.empty() ? f : sourceFace[f]; }
};

// Thrown when an input mesh cannot be used. The message is one line naming the
// element and what is wrong; callers that know the file prefix its name.
class InvalidMeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The centroid (mean of the corner positions) of a face.
Point3 faceCentroid(const PolygonMesh& mesh, int face);

// Twice-free polygon area: the sum of the areas of the fan triangles from the
// first corner. Zero exactly when all corners are collinear.
double fanArea(const PolygonMesh& mesh, int face);

// The sides of the axis-aligned bounding box (zero when empty).
Point3 boundingBoxSize(const PolygonMesh& mesh);

// Length of the diagonal of the axis-aligned bounding box (0 when empty).
double boundingBoxDiagonal(const PolygonMesh& mesh);

// "(x, y, z)" with up to 6 significant digits, for messages.
std::string formatPoint(const Point3& p);

// "(a, b, c)" for messages.
std::string formatIndexList(std::span<const int> indices);

}  // namespace rotafab::geometry
