#include "geometry/MeshMending.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>

#include "geometry/SurfaceProjection.h"

namespace rotafab::geometry {
namespace {

// No collapse turns a face by more than 60 degrees (the cosine).
constexpr double kLeastNormalCosine = 0.5;
// Two faces are merged across a band only where they turn from each other
// by less than this: the panel bends that much (posterboard does).
constexpr double kMostMergeDegrees = 30.0;

Point3 normalOf(const std::vector<Point3>& corners) {
  Point3 normal = Point3::Zero();
  for (size_t i = 0; i < corners.size(); ++i) normal += corners[i].cross(corners[(i + 1) % corners.size()]);
  return normal;
}

// The mesh's adjacency, as the collapses of one call need it: the faces
// about each vertex, and the faces on each edge.
class Collapser {
 public:
  explicit Collapser(PolygonMesh& mesh) : mesh_(mesh), facesOf_(mesh.positions.size()), moved_(facesOf_.size(), 0) {
    for (int f = 0; f < mesh.faceCount(); ++f) {
      const auto& face = mesh.faces[f];
      for (size_t i = 0; i < face.size(); ++i) {
        facesOf_[face[i]].push_back(f);
        ++sides_[key(face[i], face[(i + 1) % face.size()])];
      }
    }
    for (const auto& [edge, count] : sides_) {
      if (count == 1) boundary_.insert(edge.first), boundary_.insert(edge.second);
    }
  }

  [[nodiscard]] double length(int a, int b) const { return (mesh_.positions[a] - mesh_.positions[b]).norm(); }

  // The faces on edge (a, b).
  [[nodiscard]] std::vector<int> facesOn(int a, int b) const {
    std::vector<int> on;
    for (int f : facesOf_[a]) {
      const auto& face = mesh_.faces[f];
      for (size_t i = 0; i < face.size(); ++i) {
        const int p = face[i], q = face[(i + 1) % face.size()];
        if ((p == a && q == b) || (p == b && q == a)) on.push_back(f);
      }
    }
    return on;
  }

  // The longest side of face f.
  [[nodiscard]] std::array<int, 2> longestSide(int f) const {
    const auto& face = mesh_.faces[f];
    std::array<int, 2> best{face[0], face[1]};
    for (size_t i = 0; i < face.size(); ++i) {
      const int p = face[i], q = face[(i + 1) % face.size()];
      if (length(p, q) > length(best[0], best[1])) best = {p, q};
    }
    return best;
  }

  // The edges that may give the narrow band of (u, v) its room when they
  // go, besides its own (tried first, elsewhere): every side of the faces
  // beside it, then every edge at u or v (where a thin tube's ring or a
  // flap's rim keeps the nearer ones by the link condition); none longer
  // than `longest`, so that a collapse moves the surface by half of that at
  // most (the whole of it where one end is on the boundary and stays).
  // Shortest first within each.
  [[nodiscard]] std::vector<std::array<int, 2>> collapseCandidates(int u, int v, double longest) const {
    std::vector<std::array<int, 2>> sides, ring;
    std::set<std::pair<int, int>> seen{key(u, v)};  // (its own edge, tried first)
    const auto add = [&](std::vector<std::array<int, 2>>& to, int a, int b) {
      if (length(a, b) <= longest && seen.insert(key(a, b)).second) to.push_back({a, b});
    };
    for (int f : facesOn(u, v)) {
      const auto& face = mesh_.faces[f];
      for (size_t i = 0; i < face.size(); ++i) add(sides, face[i], face[(i + 1) % face.size()]);
    }
    for (int end : {u, v}) {
      for (int w : neighbours(end)) add(ring, end, w);
    }
    const auto shortestFirst = [&](std::vector<std::array<int, 2>>& edges) {
      std::stable_sort(edges.begin(), edges.end(),
                       [&](const auto& p, const auto& q) { return length(p[0], p[1]) < length(q[0], q[1]); });
    };
    shortestFirst(sides);
    shortestFirst(ring);
    std::vector<std::array<int, 2>> all;
    all.insert(all.end(), sides.begin(), sides.end());
    all.insert(all.end(), ring.begin(), ring.end());
    return all;
  }

  // The shortest side of face f.
  [[nodiscard]] std::array<int, 2> shortestSide(int f) const {
    const auto& face = mesh_.faces[f];
    std::array<int, 2> best{face[0], face[1]};
    for (size_t i = 0; i < face.size(); ++i) {
      const int p = face[i], q = face[(i + 1) % face.size()];
      if (length(p, q) < length(best[0], best[1])) best = {p, q};
    }
    return best;
  }

  // Where (a, b) would collapse to, if it may: its midpoint, or its end on
  // the boundary when only one end is.
  [[nodiscard]] std::optional<Point3> collapsePoint(int a, int b) const {
    if (!linkAllows(a, b)) return std::nullopt;
    const bool boundaryA = boundary_.contains(a), boundaryB = boundary_.contains(b);
    const Point3 target = boundaryA == boundaryB ? Point3((mesh_.positions[a] + mesh_.positions[b]) / 2)
                                                 : mesh_.positions[boundaryA ? a : b];
    if (!keepsFacesUpright(a, b, target)) return std::nullopt;
    return target;
  }

  // Whether `gone` may collapse into `keep`, where `keep` is: the boundary
  // keeps its place.
  [[nodiscard]] bool mayCollapseInto(int keep, int gone) const {
    if (!linkAllows(keep, gone)) return false;
    if (boundary_.contains(gone) && !boundary_.contains(keep)) return false;
    return keepsFacesUpright(keep, gone, mesh_.positions[keep]);
  }

  // Collapses (a, b) to `target`: b's faces take a, and a face left with
  // fewer than three corners is emptied (dropped by compact()). Returns
  // the farthest either end moved.
  double collapse(int a, int b, const Point3& target) {
    const double moved = std::max((mesh_.positions[a] - target).norm(), (mesh_.positions[b] - target).norm());
    // Every vertex whose adjacency this changes waits for the next call.
    for (int v : neighbours(a)) moved_[v] = 1;
    for (int v : neighbours(b)) moved_[v] = 1;
    moved_[a] = moved_[b] = 1;
    mesh_.positions[a] = target;
    for (int f : facesOf_[b]) {
      auto& face = mesh_.faces[f];
      std::replace(face.begin(), face.end(), b, a);
      face.erase(std::unique(face.begin(), face.end()), face.end());
      while (face.size() > 1 && face.front() == face.back()) face.pop_back();
      if (face.size() < 3) face.clear();
      facesOf_[a].push_back(f);
    }
    facesOf_[b].clear();
    return moved;
  }

  // Whether the two faces on inner edge (a, b) may become one: they share
  // no other corner, and turn from each other by less than kMostMergeDegrees.
  [[nodiscard]] bool mayMerge(int a, int b) const {
    if (moved_[a] || moved_[b]) return false;
    const std::vector<int> on = facesOn(a, b);
    if (on.size() != 2 || on[0] == on[1]) return false;
    const auto& f = mesh_.faces[on[0]];
    const auto& g = mesh_.faces[on[1]];
    for (int v : f) {
      if (v != a && v != b && std::find(g.begin(), g.end(), v) != g.end()) return false;
    }
    const auto normal = [&](const std::vector<int>& face) {
      std::vector<Point3> corners;
      for (int v : face) corners.push_back(mesh_.positions[v]);
      return normalOf(corners);
    };
    const Point3 n = normal(f), m = normal(g);
    if (!(n.norm() > 0 && m.norm() > 0)) return false;
    return n.normalized().dot(m.normalized()) >= std::cos(kMostMergeDegrees * std::numbers::pi / 180);
  }

  // The two faces on (a, b) made one: the first takes the second's corners
  // past the edge, the second is emptied.
  void merge(int a, int b) {
    const std::vector<int> on = facesOn(a, b);
    auto& f = mesh_.faces[on[0]];
    auto& g = mesh_.faces[on[1]];
    // Each face's corners from one end of the edge round to the other.
    const auto from = [](const std::vector<int>& face, int first) {
      const auto at = std::find(face.begin(), face.end(), first) - face.begin();
      std::vector<int> walk;
      for (size_t i = 0; i < face.size(); ++i) walk.push_back(face[(static_cast<size_t>(at) + i) % face.size()]);
      return walk;
    };
    // f runs ... x, y ... along the edge; g runs y, x.
    const auto next = [&](const std::vector<int>& face, int v) {
      const auto at = std::find(face.begin(), face.end(), v) - face.begin();
      return face[(static_cast<size_t>(at) + 1) % face.size()];
    };
    const int x = next(f, a) == b ? a : b, y = x == a ? b : a;
    std::vector<int> merged = from(f, y);      // y ... x
    const std::vector<int> rest = from(g, x);  // x ... y
    merged.insert(merged.end(), rest.begin() + 1, rest.end() - 1);
    for (int v : g) {
      moved_[v] = 1;
      for (int w : neighbours(v)) moved_[w] = 1;
      if (std::find(facesOf_[v].begin(), facesOf_[v].end(), on[0]) == facesOf_[v].end()) facesOf_[v].push_back(on[0]);
    }
    for (int v : f) moved_[v] = 1;
    f = std::move(merged);
    g.clear();
  }

  // Inner edge (a, b) of two triangles, turned to join the corners p and q
  // opposite it, where that keeps the topology (neither end left with
  // fewer than three neighbours, p and q not joined already), turns neither
  // triangle by more than 60 degrees from the pair's normal (the quad is
  // convex enough), and makes the smallest angle of the pair larger (the
  // flip toward the Delaunay triangulation widens a sliver: the bands about
  // it get the sliver's height, dissertation V.3). Returns how many radians
  // it gains, or nothing.
  [[nodiscard]] std::optional<double> flipGain(int a, int b) const {
    const auto quad = quadAbout(a, b);
    if (!quad) return std::nullopt;
    const int p = quad->p, q = quad->q;
    a = quad->a, b = quad->b;
    if (neighbours(a).size() <= 3 || neighbours(b).size() <= 3 || neighbours(p).contains(q)) return std::nullopt;
    const auto& x = mesh_.positions;
    const Point3 before = normalOf({x[a], x[b], x[p]}) + normalOf({x[b], x[a], x[q]});
    if (!(before.norm() > 0)) return std::nullopt;
    for (const std::array<int, 3>& t : {std::array{a, q, p}, std::array{q, b, p}}) {
      const Point3 n = normalOf({x[t[0]], x[t[1]], x[t[2]]});
      if (!(n.norm() > 0) || n.normalized().dot(before.normalized()) < kLeastNormalCosine) return std::nullopt;
    }
    const double was = std::min(smallestAngle(a, b, p), smallestAngle(b, a, q));
    const double is = std::min(smallestAngle(a, q, p), smallestAngle(q, b, p));
    if (!(is > was)) return std::nullopt;
    return is - was;
  }

  // Flips (a, b) (flipGain() allowed it). Returns how far the surface
  // moved: the distance between the old diagonal and the new.
  double flip(int a, int b) {
    const Quad quad = *quadAbout(a, b);
    const int f = quad.f, g = quad.g, p = quad.p, q = quad.q;
    a = quad.a, b = quad.b;
    for (int v : {a, b, p, q}) {
      moved_[v] = 1;
      for (int w : neighbours(v)) moved_[w] = 1;
    }
    // f runs a, b, p and g runs b, a, q: the quad is a, q, b, p.
    mesh_.faces[f] = {a, q, p};
    mesh_.faces[g] = {q, b, p};
    std::erase(facesOf_[a], g);
    std::erase(facesOf_[b], f);
    facesOf_[p].push_back(g);
    facesOf_[q].push_back(f);
    const auto& x = mesh_.positions;
    return segmentDistance(x[a], x[b], x[p], x[q]);
  }

  // The faces emptied and the vertices no face uses, gone.
  void compact() {
    PolygonMesh kept;
    std::vector<int> index(mesh_.positions.size(), -1);
    for (int f = 0; f < mesh_.faceCount(); ++f) {
      if (mesh_.faces[f].empty()) continue;
      std::vector<int> face;
      for (int v : mesh_.faces[f]) {
        if (index[v] < 0) {
          index[v] = kept.vertexCount();
          kept.positions.push_back(mesh_.positions[v]);
          kept.sourceVertex.push_back(mesh_.sourceVertexIndex(v));
        }
        face.push_back(index[v]);
      }
      kept.faces.push_back(std::move(face));
      kept.sourceFace.push_back(mesh_.sourceFaceIndex(f));
    }
    mesh_ = std::move(kept);
  }

 private:
  static std::pair<int, int> key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

  // Whether collapsing (a, b) keeps the topology: neither end moved by this
  // call, an edge, not an inner edge across the boundary, and the link
  // condition: a and b share no neighbour but the corners opposite the
  // edge in its triangles, and no face holds both apart.
  [[nodiscard]] bool linkAllows(int a, int b) const {
    if (a == b || moved_[a] || moved_[b]) return false;
    const std::vector<int> on = facesOn(a, b);
    if (on.empty()) return false;
    if (boundary_.contains(a) && boundary_.contains(b) && on.size() != 1) return false;
    std::set<int> opposite;
    for (int f : on) {
      const auto& face = mesh_.faces[f];
      if (face.size() == 3) {
        for (int v : face) {
          if (v != a && v != b) opposite.insert(v);
        }
      }
    }
    std::set<int> common;
    const std::set<int> nearA = neighbours(a);
    for (int v : neighbours(b)) {
      if (nearA.contains(v)) common.insert(v);
    }
    if (common != opposite) return false;
    for (int f : facesOf_[a]) {
      const auto& face = mesh_.faces[f];
      if (std::find(face.begin(), face.end(), b) != face.end() && std::find(on.begin(), on.end(), f) == on.end()) {
        return false;
      }
    }
    return true;
  }

  // Whether a and b moved to `target` turn no face about them by more than
  // 60 degrees, nor leave one flat (a face of no area before, a degenerate
  // one, may stay so).
  [[nodiscard]] bool keepsFacesUpright(int a, int b, const Point3& target) const {
    std::set<int> around(facesOf_[a].begin(), facesOf_[a].end());
    around.insert(facesOf_[b].begin(), facesOf_[b].end());
    for (int f : around) {
      std::vector<Point3> before, after;
      for (int v : mesh_.faces[f]) {
        before.push_back(mesh_.positions[v]);
        const Point3 p = v == a || v == b ? target : mesh_.positions[v];
        if (after.empty() || !(after.back() - p).isZero(0)) after.push_back(p);
      }
      while (after.size() > 1 && (after.front() - after.back()).isZero(0)) after.pop_back();
      if (after.size() < 3) continue;  // the face vanishes with the edge
      const Point3 n0 = normalOf(before), n1 = normalOf(after);
      if (!(n0.norm() > 0)) continue;
      if (n1.norm() <= 1e-9 * n0.norm()) return false;
      if (n0.normalized().dot(n1.normalized()) < kLeastNormalCosine) return false;
    }
    return true;
  }

  // The two triangles on inner edge (a, b), unmoved by this call: f runs
  // a, b, p and g runs b, a, q (a and b swapped where the edge runs the
  // other way in f).
  struct Quad {
    int f, g, p, q, a, b;
  };
  [[nodiscard]] std::optional<Quad> quadAbout(int a, int b) const {
    if (moved_[a] || moved_[b]) return std::nullopt;
    const std::vector<int> on = facesOn(a, b);
    if (on.size() != 2 || on[0] == on[1]) return std::nullopt;
    for (int f : on) {
      if (mesh_.faces[f].size() != 3) return std::nullopt;
    }
    const auto third = [&](int f) {
      for (int v : mesh_.faces[f]) {
        if (v != a && v != b) return v;
      }
      return -1;
    };
    const auto runs = [&](int f, int from, int to) {
      const auto& t = mesh_.faces[f];
      for (size_t i = 0; i < 3; ++i) {
        if (t[i] == from && t[(i + 1) % 3] == to) return true;
      }
      return false;
    };
    int f = on[0], g = on[1];
    if (!runs(f, a, b)) std::swap(a, b);
    if (!runs(f, a, b) || !runs(g, b, a)) return std::nullopt;
    const int p = third(f), q = third(g);
    if (p < 0 || q < 0 || p == q || moved_[p] || moved_[q]) return std::nullopt;
    return Quad{f, g, p, q, a, b};
  }

  // The smallest angle of triangle (a, b, c), radians.
  [[nodiscard]] double smallestAngle(int a, int b, int c) const {
    const auto& x = mesh_.positions;
    const auto angle = [&](int at, int u, int v) {
      const Point3 e = x[u] - x[at], h = x[v] - x[at];
      return std::atan2(e.cross(h).norm(), e.dot(h));
    };
    return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
  }

  // The distance between segments (a, b) and (c, d), to a 64th of the
  // first's length (for a repair's report, not for geometry).
  static double segmentDistance(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
    double nearest = std::numeric_limits<double>::max();
    for (int i = 0; i <= 64; ++i) {
      const Point3 p = a + (b - a) * (i / 64.0);
      nearest = std::min(nearest, (projection::closestOnSegment(p, c, d) - p).norm());
    }
    return nearest;
  }

  [[nodiscard]] std::set<int> neighbours(int v) const {
    std::set<int> near;
    for (int f : facesOf_[v]) {
      const auto& face = mesh_.faces[f];
      for (size_t i = 0; i < face.size(); ++i) {
        if (face[i] != v) continue;
        near.insert(face[(i + 1) % face.size()]);
        near.insert(face[(i + face.size() - 1) % face.size()]);
      }
    }
    return near;
  }

  PolygonMesh& mesh_;
  std::vector<std::vector<int>> facesOf_;
  std::map<std::pair<int, int>, int> sides_;
  std::set<int> boundary_;
  std::vector<char> moved_;
};

// Where no edge about the narrow band of (u, v) may collapse: the flip
// (Collapser::flipGain()) that widens its faces most, of its own edge and
// the longest side of each face beside it (a sliver's). Says whether it
// flipped one.
bool flippedNear(Collapser& collapser, const PolygonMesh& mesh, int u, int v, MeshRepair& flipped) {
  std::vector<std::array<int, 2>> candidates{{u, v}};
  for (int f : collapser.facesOn(u, v)) candidates.push_back(collapser.longestSide(f));
  std::optional<std::array<int, 2>> best;
  double most = 0;
  for (const auto& [a, b] : candidates) {
    const std::optional<double> gain = collapser.flipGain(a, b);
    if (gain && *gain > most) most = *gain, best = std::array{a, b};
  }
  if (!best) return false;
  if (flipped.count == 0) {
    flipped.first =
        fmt::format("edge ({}, {})", mesh.sourceVertexIndex((*best)[0]), mesh.sourceVertexIndex((*best)[1]));
  }
  flipped.moved = std::max(flipped.moved, collapser.flip((*best)[0], (*best)[1]));
  ++flipped.count;
  return true;
}

}  // namespace

void Mends::add(const Mends& later) {
  for (const auto& [sum, more] :
       {std::pair{&collapsed, &later.collapsed}, {&flipped, &later.flipped}, {&merged, &later.merged}}) {
    if (sum->count == 0) sum->first = more->first;
    sum->count += more->count;
    sum->moved = std::max(sum->moved, more->moved);
  }
}

MeshRepair collapseDegenerateFaces(PolygonMesh& mesh) {
  MeshRepair repair{"collapse-degenerate-face", 0, ""};
  // Each pass collapses where no earlier collapse of it moved a vertex.
  for (bool again = true; again;) {
    again = false;
    const double diagonal = boundingBoxDiagonal(mesh);
    const double least = 1e-12 * diagonal * diagonal;
    Collapser collapser(mesh);
    for (int f = 0; f < mesh.faceCount(); ++f) {
      const std::vector<int> face = mesh.faces[f];
      if (face.size() < 3 || fanArea(mesh, f) > least) continue;
      // Its sides, shortest first: the shorter end of the shortest goes into the other.
      std::vector<std::array<int, 2>> sides;
      for (size_t i = 0; i < face.size(); ++i) sides.push_back({face[i], face[(i + 1) % face.size()]});
      std::stable_sort(sides.begin(), sides.end(), [&](const auto& p, const auto& q) {
        return collapser.length(p[0], p[1]) < collapser.length(q[0], q[1]);
      });
      const auto collapseOne = [&] {
        for (const auto& [p, q] : sides) {
          for (const auto& [keep, gone] : {std::pair{p, q}, std::pair{q, p}}) {
            if (!collapser.mayCollapseInto(keep, gone)) continue;
            if (repair.count == 0) repair.first = fmt::format("face {}", mesh.sourceFaceIndex(f));
            repair.moved = std::max(repair.moved, collapser.collapse(keep, gone, mesh.positions[keep]));
            ++repair.count;
            return true;
          }
        }
        return false;
      };
      again = collapseOne() || again;
    }
    if (again) collapser.compact();
  }
  return repair;
}

Mends mendNarrowPlaces(PolygonMesh& mesh, const std::vector<std::array<int, 2>>& places, bool merges, bool flipsFirst) {
  Mends mends;
  MeshRepair& repair = mends.collapsed;
  MeshRepair& merged = mends.merged;
  Collapser collapser(mesh);
  double sides = 0, sideCount = 0;
  for (const auto& face : mesh.faces) {
    for (size_t i = 0; i < face.size(); ++i) {
      sides += (mesh.positions[face[i]] - mesh.positions[face[(i + 1) % face.size()]]).norm();
      ++sideCount;
    }
  }
  const double meanEdge = sideCount > 0 ? sides / sideCount : 0;
  // Collapses the first of `edges` that may go; says whether one did.
  const auto collapsedOne = [&](const std::vector<std::array<int, 2>>& edges) {
    for (const auto& [a, b] : edges) {
      const std::optional<Point3> target = collapser.collapsePoint(a, b);
      if (!target) continue;
      if (repair.count == 0) {
        repair.first = fmt::format("edge ({}, {})", mesh.sourceVertexIndex(a), mesh.sourceVertexIndex(b));
      }
      repair.moved = std::max(repair.moved, collapser.collapse(a, b, *target));
      ++repair.count;
      return true;
    }
    return false;
  };
  for (const auto& [u, v] : places) {
    if (u < 0 || v < 0 || u >= mesh.vertexCount() || v >= mesh.vertexCount()) continue;
    // The shortest that may go of the band's own edge and the shortest side of each face beside it.
    std::vector<std::array<int, 2>> candidates{{u, v}};
    for (int f : collapser.facesOn(u, v)) candidates.push_back(collapser.shortestSide(f));
    std::stable_sort(candidates.begin(), candidates.end(), [&](const auto& p, const auto& q) {
      return collapser.length(p[0], p[1]) < collapser.length(q[0], q[1]);
    });
    bool mended = flipsFirst && flippedNear(collapser, mesh, u, v, mends.flipped);
    if (!mended) mended = collapsedOne(candidates);
    if (!mended && !flipsFirst) mended = flippedNear(collapser, mesh, u, v, mends.flipped);
    if (!mended && merges && collapser.mayMerge(u, v)) {
      if (merged.count == 0)
        merged.first = fmt::format("edge ({}, {})", mesh.sourceVertexIndex(u), mesh.sourceVertexIndex(v));
      collapser.merge(u, v);
      ++merged.count;
      mended = true;
    }
    // Last, any edge about the band that may go (a thin tube's ring, a
    // flap's rim), no longer than the mesh's mean edge.
    if (!mended) collapsedOne(collapser.collapseCandidates(u, v, meanEdge));
  }
  if (mends.count() > 0) collapser.compact();
  return mends;
}

}  // namespace rotafab::geometry
