#pragma once
// A graph rotation system (dissertation III.1.1) with extended edge twists
// (III.1.2), stored as darts: dart 2e and 2e+1 are the two ends of edge e, a
// dart points away from its origin vertex. The rotation at a vertex is the
// cyclic order of its darts; `rotate(d)` is the next dart after d in that order.
//
// Built from an oriented manifold polygon mesh: the rotation is the one the
// embedding induces, chosen so that face tracing with no twists returns the
// mesh's faces as they are listed (each face's darts in its own order). A
// boundary is handled by one extra "boundary walk" per boundary loop: the darts
// on the open side of a boundary edge have no face, and the rotation passes
// from the last face around a boundary vertex across that gap.
//
// Requires a mesh that analyzeMesh() found usable (manifold, orientable, no
// repeated corners). Throws InvalidMeshError otherwise.

#include <vector>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

using Dart = int;

class RotationSystem {
 public:
  static RotationSystem fromMesh(const PolygonMesh& mesh);

  [[nodiscard]] int vertexCount() const { return vertexCount_; }
  [[nodiscard]] int edgeCount() const { return static_cast<int>(twist_.size()); }
  [[nodiscard]] int dartCount() const { return static_cast<int>(origin_.size()); }

  [[nodiscard]] static Dart reverse(Dart d) { return d ^ 1; }
  [[nodiscard]] static int edgeOf(Dart d) { return d >> 1; }
  [[nodiscard]] int origin(Dart d) const { return origin_[d]; }
  [[nodiscard]] int target(Dart d) const { return origin_[reverse(d)]; }
  // The mesh face on the left of d as its face lists it, or -1 on the open side of a boundary.
  [[nodiscard]] int face(Dart d) const { return face_[d]; }
  [[nodiscard]] bool isBoundary(Dart d) const { return face_[d] < 0; }
  [[nodiscard]] bool isBoundaryEdge(int e) const { return face_[2 * e] < 0 || face_[2 * e + 1] < 0; }

  // The successor of d in the rotation at origin(d), and its predecessor.
  [[nodiscard]] Dart rotate(Dart d) const { return faceNext_[reverse(d)]; }
  [[nodiscard]] Dart rotateBack(Dart d) const { return reverse(facePrev_[d]); }
  // The dart after d along its (untwisted) face or boundary walk.
  [[nodiscard]] Dart faceNext(Dart d) const { return faceNext_[d]; }
  [[nodiscard]] Dart facePrev(Dart d) const { return facePrev_[d]; }

  // Some dart leaving v; on a boundary vertex, the one on the open side.
  [[nodiscard]] Dart dartFrom(int v) const { return outgoing_[v]; }
  // The darts leaving v, counter-clockwise seen from outside (rotateBack order),
  // starting with dartFrom(v).
  [[nodiscard]] std::vector<Dart> dartsAround(int v) const;
  // The dart of face f's first corner (it leaves faces[f][0]); faceNext walks the rest in order.
  [[nodiscard]] Dart faceDart(int f) const { return faceDart_[f]; }
  [[nodiscard]] int valence(int v) const;
  [[nodiscard]] bool isBoundaryVertex(int v) const;

  // Extended twist (III.1.2): k > 0 for a k+-twisted edge, k < 0 for k-.
  // Face tracing uses its parity as the edge type.
  [[nodiscard]] int twist(int e) const { return twist_[e]; }
  void setTwist(int e, int k) { twist_[e] = k; }
  void twistAll(int k) { std::fill(twist_.begin(), twist_.end(), k); }

 private:
  int vertexCount_ = 0;
  std::vector<int> origin_;
  std::vector<int> face_;
  std::vector<Dart> faceNext_;
  std::vector<Dart> facePrev_;
  std::vector<Dart> outgoing_;
  std::vector<Dart> faceDart_;
  std::vector<int> twist_;
};

}  // namespace rotafab::geometry
