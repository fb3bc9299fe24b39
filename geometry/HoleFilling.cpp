#include "geometry/HoleFilling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "geometry/RotationSystem.h"

namespace rotafab::geometry {
namespace {

// Each boundary loop as the corners of the face that would close it: the
// walk of its boundary darts, which runs against the faces around it.
std::vector<std::vector<int>> boundaryLoops(const PolygonMesh& mesh) {
  const auto rs = RotationSystem::fromMesh(mesh);
  std::vector<std::vector<int>> loops;
  std::vector<char> walked(rs.dartCount(), 0);
  for (Dart d = 0; d < rs.dartCount(); ++d) {
    if (!rs.isBoundary(d) || walked[d]) continue;
    std::vector<int> loop;
    for (Dart e = d; !walked[e]; e = rs.faceNext(e)) {
      walked[e] = 1;
      loop.push_back(rs.origin(e));
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

void markSources(PolygonMesh& mesh) {
  if (mesh.sourceFace.empty()) {
    mesh.sourceFace.resize(mesh.faces.size());
    std::iota(mesh.sourceFace.begin(), mesh.sourceFace.end(), 0);
  }
  if (mesh.sourceVertex.empty()) {
    mesh.sourceVertex.resize(mesh.positions.size());
    std::iota(mesh.sourceVertex.begin(), mesh.sourceVertex.end(), 0);
  }
}

using Triangle = std::array<int, 3>;

std::uint64_t edgeKey(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

// One hole's patch: triangles over the mesh's vertices and its own new
// ones, each directed edge mapped to its triangle so that an edge can be
// split or flipped in place.
class Patch {
 public:
  Patch(std::vector<Point3>& positions, const std::vector<int>& loop, const std::vector<std::vector<int>>& faces)
      : positions_(positions), firstNew_(static_cast<int>(positions.size())) {
    // The mesh's edges between the loop's vertices: a chord or a flip must
    // not add a second copy of one (an edge with three faces).
    const std::unordered_set<int> onLoop(loop.begin(), loop.end());
    for (const auto& face : faces) {
      for (size_t i = 0; i < face.size(); ++i) {
        const int a = face[i], b = face[(i + 1) % face.size()];
        if (onLoop.contains(a) && onLoop.contains(b)) meshEdges_.insert(edgeKey(std::min(a, b), std::max(a, b)));
      }
    }
    // The normal of the face beside each side of the loop (the patch runs
    // along it from loop[k] to loop[k + 1], that face the other way).
    std::unordered_map<std::uint64_t, const std::vector<int>*> faceOfSide;
    for (const auto& face : faces) {
      for (size_t i = 0; i < face.size(); ++i) {
        const int a = face[i], b = face[(i + 1) % face.size()];
        if (onLoop.contains(a) && onLoop.contains(b)) faceOfSide[edgeKey(a, b)] = &face;
      }
    }
    for (size_t k = 0; k < loop.size(); ++k) {
      const int a = loop[k], b = loop[(k + 1) % loop.size()];
      const auto beside = faceOfSide.find(edgeKey(b, a));
      if (beside == faceOfSide.end()) continue;
      const auto& face = *beside->second;
      Point3 normal = Point3::Zero();
      for (size_t c = 0; c < face.size(); ++c) normal += point(face[c]).cross(point(face[(c + 1) % face.size()]));
      if (normal.norm() > 0) besideNormal_[edgeKey(a, b)] = normal.normalized();
    }
    double perimeter = 0;
    for (size_t i = 0; i < loop.size(); ++i) perimeter += (point(loop[(i + 1) % loop.size()]) - point(loop[i])).norm();
    // The loop's own edge length, or longer where a patch of those would
    // pass kMostTriangles (a disc of this perimeter, in equilateral
    // triangles): a hole of thousands of corners is not worth millions of
    // panels.
    const double discArea = perimeter * perimeter / (4 * std::numbers::pi);
    target_ = std::max(perimeter / static_cast<double>(loop.size()),
                       std::sqrt(discArea / (kMostTriangles * std::sqrt(3.0) / 4)));
    if (!triangulateLeastArea(loop)) fan(loop);
  }

  // Liepa's refinement, simplified to one density (the loop's mean edge):
  // split what is too long, flip towards Delaunay, fair; until nothing is
  // split.
  void refine() {
    for (int round = 0; round < 64; ++round) {
      const bool split = splitLongEdges();
      flipTowardsDelaunay();
      fair();
      if (!split) break;
    }
  }

  [[nodiscard]] const std::vector<Triangle>& triangles() const { return triangles_; }

 private:
  [[nodiscard]] const Point3& point(int v) const { return positions_[static_cast<size_t>(v)]; }
  [[nodiscard]] bool isNew(int v) const { return v >= firstNew_; }
  [[nodiscard]] bool isEdge(int a, int b) const {
    return meshEdges_.contains(edgeKey(std::min(a, b), std::max(a, b))) || triangleOf_.contains(edgeKey(a, b)) ||
           triangleOf_.contains(edgeKey(b, a));
  }
  [[nodiscard]] double longestSquared(int a, int b, int c) const {
    return std::max({(point(b) - point(a)).squaredNorm(), (point(c) - point(b)).squaredNorm(),
                     (point(a) - point(c)).squaredNorm()});
  }
  // A triangle's area over its longest side squared below which it is a
  // sliver (a corner of about a tenth of a degree).
  static constexpr double kLeastAreaPerSquaredLength = 1e-3;
  [[nodiscard]] bool isSliver(int a, int b, int c) const {
    return area(a, b, c) <= kLeastAreaPerSquaredLength * longestSquared(a, b, c);
  }
  [[nodiscard]] double area(int a, int b, int c) const {
    return (point(b) - point(a)).cross(point(c) - point(a)).norm() / 2;
  }

  void set(int t, const Triangle& triangle) {
    auto& slot = triangles_[static_cast<size_t>(t)];
    for (int i = 0; i < 3; ++i) {
      const auto at = triangleOf_.find(edgeKey(slot[i], slot[(i + 1) % 3]));
      if (at != triangleOf_.end() && at->second == t) triangleOf_.erase(at);
    }
    slot = triangle;
    for (int i = 0; i < 3; ++i) triangleOf_[edgeKey(slot[i], slot[(i + 1) % 3])] = t;
  }
  void add(const Triangle& triangle) {
    triangles_.push_back({-1, -1, -1});
    set(static_cast<int>(triangles_.size()) - 1, triangle);
  }
  // The corner of triangle t that is neither a nor b.
  [[nodiscard]] int third(int t, int a, int b) const {
    for (const int v : triangles_[static_cast<size_t>(t)]) {
      if (v != a && v != b) return v;
    }
    return -1;
  }
  int newVertex(const Point3& p) {
    positions_.push_back(p);
    return static_cast<int>(positions_.size()) - 1;
  }

  // The triangulation of least area over the loop's own corners (Liepa
  // 2003, section 3, with area alone as the weight): O(n^3), so for loops
  // of up to kMostCorners; false when no chord set avoids the mesh's edges.
  bool triangulateLeastArea(const std::vector<int>& loop) {
    constexpr size_t kMostCorners = 400;
    const size_t n = loop.size();
    if (n > kMostCorners) return false;
    constexpr double kNone = std::numeric_limits<double>::infinity();
    std::vector<double> weight(n * n, 0.0);
    std::vector<int> middle(n * n, -1);
    const auto chordAllowed = [&](size_t i, size_t j) {
      return j == i + 1 || (i == 0 && j == n - 1) ||
             (loop[i] != loop[j] &&
              !meshEdges_.contains(edgeKey(std::min(loop[i], loop[j]), std::max(loop[i], loop[j]))));
    };
    for (size_t span = 2; span < n; ++span) {
      for (size_t i = 0; i + span < n; ++i) {
        const size_t j = i + span;
        double best = kNone;
        if (chordAllowed(i, j)) {
          for (size_t m = i + 1; m < j; ++m) {
            // Not three corners in a line (a straight stretch of the loop),
            // which would cost nothing and give a triangle of no area.
            if (isSliver(loop[i], loop[m], loop[j])) continue;
            const double a = area(loop[i], loop[m], loop[j]);
            if (foldsBack({loop[i], loop[m], loop[j]})) continue;
            const double w = weight[i * n + m] + weight[m * n + j] + a;
            if (w < best) best = w, middle[i * n + j] = static_cast<int>(m);
          }
        }
        weight[i * n + j] = best;
      }
    }
    if (!(weight[n - 1] < kNone)) return false;
    std::vector<std::pair<size_t, size_t>> pending{{0, n - 1}};
    while (!pending.empty()) {
      const auto [i, j] = pending.back();
      pending.pop_back();
      if (j < i + 2) continue;
      const auto m = static_cast<size_t>(middle[i * n + j]);
      add({loop[i], loop[m], loop[j]});  // the loop's order: oriented like the cap
      pending.push_back({i, m});
      pending.push_back({m, j});
    }
    return true;
  }

  // Whether a triangle with a side on the loop folds back over the mesh's
  // face across that side (Liepa weighs the dihedral angle first for
  // this): the least area would often lay an ear of a bent hole flat on the
  // face beside it, and a flip or the fairing can too.
  [[nodiscard]] bool foldsBack(const Triangle& triangle) const { return turnFromBeside(triangle) < kMostFoldCosine; }
  // The least cosine between the triangle's normal and the normals of the
  // faces beside its sides on the loop (1 when none is on the loop).
  [[nodiscard]] double turnFromBeside(const Triangle& triangle) const {
    const Point3 normal = (point(triangle[1]) - point(triangle[0])).cross(point(triangle[2]) - point(triangle[0]));
    double least = 1;
    for (int k = 0; k < 3; ++k) {
      const auto beside = besideNormal_.find(edgeKey(triangle[k], triangle[(k + 1) % 3]));
      if (beside == besideNormal_.end()) continue;
      least = std::min(least, normal.norm() > 0 ? normal.dot(beside->second) / normal.norm() : -1.0);
    }
    return least;
  }

  // A fan from a new vertex at the loop's centroid: always a valid start.
  void fan(const std::vector<int>& loop) {
    Point3 centre = Point3::Zero();
    for (const int v : loop) centre += point(v);
    const int c = newVertex(centre / static_cast<double>(loop.size()));
    for (size_t i = 0; i < loop.size(); ++i) add({loop[i], loop[(i + 1) % loop.size()], c});
  }

  // The patch's inner edges (both sides in the patch), each once.
  [[nodiscard]] std::vector<std::pair<int, int>> innerEdges() const {
    std::vector<std::pair<int, int>> edges;
    for (const auto& [key, t] : triangleOf_) {
      const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
      if (a < b && triangleOf_.contains(edgeKey(b, a))) edges.emplace_back(a, b);
    }
    std::sort(edges.begin(), edges.end());  // (the map's order is not the same from run to run)
    return edges;
  }

  bool splitLongEdges() {
    const double longest = target_ * 4 / 3;
    auto edges = innerEdges();
    const auto length = [&](const std::pair<int, int>& e) { return (point(e.second) - point(e.first)).norm(); };
    std::erase_if(edges, [&](const auto& e) { return length(e) <= longest; });
    std::stable_sort(edges.begin(), edges.end(), [&](const auto& x, const auto& y) { return length(x) > length(y); });
    bool split = false;
    for (const auto& [a, b] : edges) {
      const auto ab = triangleOf_.find(edgeKey(a, b)), ba = triangleOf_.find(edgeKey(b, a));
      if (ab == triangleOf_.end() || ba == triangleOf_.end()) continue;
      const int t1 = ab->second, t2 = ba->second, c = third(t1, a, b), d = third(t2, b, a);
      const int m = newVertex((point(a) + point(b)) / 2);
      set(t1, {a, m, c});
      add({m, b, c});
      set(t2, {b, m, d});
      add({m, a, d});
      split = true;
    }
    return split;
  }

  [[nodiscard]] double angleAt(int apex, int a, int b) const {
    const Point3 u = point(a) - point(apex), v = point(b) - point(apex);
    return std::atan2(u.cross(v).norm(), u.dot(v));
  }

  void flipTowardsDelaunay() {
    for (int sweep = 0; sweep < 8; ++sweep) {
      bool flipped = false;
      for (const auto& [a, b] : innerEdges()) {
        const auto ab = triangleOf_.find(edgeKey(a, b)), ba = triangleOf_.find(edgeKey(b, a));
        if (ab == triangleOf_.end() || ba == triangleOf_.end()) continue;
        const int t1 = ab->second, t2 = ba->second, c = third(t1, a, b), d = third(t2, b, a);
        if (c == d || isEdge(c, d)) continue;
        if (angleAt(c, a, b) + angleAt(d, b, a) <= std::numbers::pi + 1e-9) continue;
        // Not where the two new triangles would fold onto each other.
        const Point3 n1 = (point(d) - point(a)).cross(point(c) - point(a)),
                     n2 = (point(c) - point(b)).cross(point(d) - point(b));
        if (!(n1.dot(n2) > 0) || foldsBack({a, d, c}) || foldsBack({b, c, d}) || isSliver(a, d, c) ||
            isSliver(b, c, d)) {
          continue;
        }
        set(t1, {a, d, c});
        set(t2, {b, c, d});
        flipped = true;
      }
      if (!flipped) break;
    }
  }

  // Umbrella smoothing of the new vertices, the loop held (Liepa's fairing
  // at its first order: a membrane over the hole).
  void fair() {
    const size_t first = static_cast<size_t>(firstNew_), count = positions_.size() - first;
    if (count == 0) return;
    std::vector<Point3> sum(count);
    std::vector<int> neighbours(count);
    std::vector<std::vector<int>> trianglesAt(count);
    for (size_t t = 0; t < triangles_.size(); ++t) {
      for (const int v : triangles_[t]) {
        if (isNew(v)) trianglesAt[static_cast<size_t>(v) - first].push_back(static_cast<int>(t));
      }
    }
    for (int iteration = 0; iteration < 10; ++iteration) {
      std::fill(sum.begin(), sum.end(), Point3::Zero());
      std::fill(neighbours.begin(), neighbours.end(), 0);
      // Around an inner vertex each triangle has one side leaving it: each
      // neighbour is counted once.
      for (const auto& triangle : triangles_) {
        for (int i = 0; i < 3; ++i) {
          if (!isNew(triangle[i])) continue;
          const size_t v = static_cast<size_t>(triangle[i]) - first;
          sum[v] += point(triangle[(i + 1) % 3]);
          ++neighbours[v];
        }
      }
      for (size_t v = 0; v < count; ++v) {
        if (neighbours[v] == 0) continue;
        const auto& around = trianglesAt[v];
        const auto leastTurn = [&] {
          double least = 1;
          for (const int t : around) least = std::min(least, turnFromBeside(triangles_[static_cast<size_t>(t)]));
          return least;
        };
        const double turnBefore = leastTurn();
        const Point3 before = positions_[first + v];
        positions_[first + v] = sum[v] / neighbours[v];
        // Not onto the face beside the hole: undone where it folds further
        // back than allowed and than it was (a vertex already folded may move out).
        const double turnAfter = leastTurn();
        if (turnAfter < kMostFoldCosine && turnAfter < turnBefore) positions_[first + v] = before;
      }
    }
  }

  std::vector<Point3>& positions_;
  const int firstNew_;
  double target_ = 0;
  std::vector<Triangle> triangles_;
  std::unordered_map<std::uint64_t, int> triangleOf_;  // directed edge -> its triangle
  std::unordered_set<std::uint64_t> meshEdges_;        // undirected, between the loop's vertices
  // Of the face beside each side of the loop, unit, by the side as the patch runs along it.
  std::unordered_map<std::uint64_t, Point3> besideNormal_;
  // A patch's face beside the loop may turn from the mesh's by at most
  // about 120 degrees (a hole's rim can be a right angle, as where a tube's
  // end is closed; it cannot lie back on the surface).
  static constexpr double kMostFoldCosine = -0.5;
  // The disc's triangles at the target length, which the refinement's
  // edges (2/3 to 4/3 of it) and the loop's shorter ones make about half as
  // many again: about 20,000 a patch at most.
  static constexpr double kMostTriangles = 13000;
};

}  // namespace

int fillHoles(PolygonMesh& mesh) {
  const auto loops = boundaryLoops(mesh);
  markSources(mesh);
  for (const auto& loop : loops) {
    mesh.faces.push_back(loop);
    mesh.sourceFace.push_back(-1);  // no face of the file: the manifest says "cap"
  }
  return static_cast<int>(loops.size());
}

int patchHoles(PolygonMesh& mesh) {
  const auto loops = boundaryLoops(mesh);
  markSources(mesh);
  for (const auto& loop : loops) {
    Patch patch(mesh.positions, loop, mesh.faces);
    patch.refine();
    for (const auto& triangle : patch.triangles()) {
      mesh.faces.push_back({triangle[0], triangle[1], triangle[2]});
      mesh.sourceFace.push_back(-1);
    }
    mesh.sourceVertex.resize(mesh.positions.size(), -1);  // the patch's own vertices: none in the file
  }
  return static_cast<int>(loops.size());
}

}  // namespace rotafab::geometry
