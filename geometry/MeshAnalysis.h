#pragma once
// Topology and validity of an imported mesh: the counts of `inspect`
// (docs/CONTRACT.md, "inspect"), the problems that make a mesh unusable for
// construction (named element by element), and the repair of an inconsistent
// orientation.

#include <optional>
#include <string>
#include <vector>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct MeshTopology {
  int vertices = 0;
  int edges = 0;
  int faces = 0;
  int boundaryLoops = 0;
  int components = 0;
  int euler = 0;             // V - E + F
  std::optional<int> genus;  // after capping each boundary loop; summed over components; only
                             // for orientable manifolds
  bool orientable = false;
  bool manifold = false;
};

enum class MeshProblemKind { RepeatedCorner, ZeroAreaFace, NonManifoldEdge, BowTieVertex, NonOrientable };

struct MeshProblem {
  MeshProblemKind kind;
  std::string message;  // one line, no file name
};

struct MeshAnalysis {
  MeshTopology topology;
  std::vector<MeshProblem> problems;
  int flippedFaces = 0;            // faces reversed to make the orientation consistent
  int firstFlippedFace = -1;       // the lowest of them (an index in the mesh), -1: none
  std::vector<std::string> notes;  // what was repaired, for people

  [[nodiscard]] bool usable() const { return problems.empty(); }
};

// Analyses the mesh and, where the surface is orientable, reverses faces so
// that all faces of a component agree (and, on a closed component, face
// outwards: positive enclosed volume).
MeshAnalysis analyzeMesh(PolygonMesh& mesh);

// Throws InvalidMeshError naming the first problem (and how many more) unless
// the mesh is usable for construction.
void requireUsable(const MeshAnalysis& analysis);

}  // namespace rotafab::geometry
