#pragma once
// The sides of a polygon mesh's edges, and the corners around its vertices:
// what the analysis (MeshAnalysis.cpp) and the repair (MeshRepair.cpp) walk
// to find non-manifold edges and the fans of faces around each vertex.

#include <algorithm>
#include <numeric>
#include <tuple>
#include <vector>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

class DisjointSets {
 public:
  explicit DisjointSets(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

// One side of an edge: face `face` runs from `from` to `to` at corner `corner`
// (the corner of `from`; corners are numbered over all faces in order).
struct EdgeUse {
  int low, high;  // the edge's endpoints, low < high
  int face;
  int corner;
  bool forward;  // from == low
};

struct EdgeUses {
  std::vector<int> firstCorner;  // per face, and the corner count at the end
  std::vector<EdgeUse> uses;     // every side of every edge, by (low, high, face)

  explicit EdgeUses(const PolygonMesh& mesh) : firstCorner(mesh.faces.size() + 1, 0) {
    for (size_t f = 0; f < mesh.faces.size(); ++f)
      firstCorner[f + 1] = firstCorner[f] + static_cast<int>(mesh.faces[f].size());
    uses.reserve(firstCorner.back());
    for (int f = 0; f < mesh.faceCount(); ++f) {
      const auto& face = mesh.faces[f];
      for (size_t i = 0; i < face.size(); ++i) {
        const int from = face[i], to = face[(i + 1) % face.size()];
        uses.push_back({std::min(from, to), std::max(from, to), f, firstCorner[f] + static_cast<int>(i), from < to});
      }
    }
    std::sort(uses.begin(), uses.end(), [](const EdgeUse& a, const EdgeUse& b) {
      return std::tie(a.low, a.high, a.face) < std::tie(b.low, b.high, b.face);
    });
  }

  [[nodiscard]] int cornerCount() const { return firstCorner.back(); }

  // The corner of the use's face at `vertex`, one of the edge's ends.
  [[nodiscard]] int cornerAt(const EdgeUse& use, int vertex) const {
    if (vertex == (use.forward ? use.low : use.high)) return use.corner;
    const int size = firstCorner[use.face + 1] - firstCorner[use.face];
    return firstCorner[use.face] + (use.corner - firstCorner[use.face] + 1) % size;
  }

  // Calls visit(begin, end) for the uses of each edge in turn: [begin, end).
  template <typename Visit>
  void forEachEdge(Visit&& visit) const {
    for (size_t begin = 0, end = 0; begin < uses.size(); begin = end) {
      while (end < uses.size() && uses[end].low == uses[begin].low && uses[end].high == uses[begin].high) ++end;
      visit(begin, end);
    }
  }
};

}  // namespace rotafab::geometry
