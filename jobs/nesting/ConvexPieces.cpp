#include "jobs/nesting/ConvexPieces.h"

#include <algorithm>
#include <map>
#include <utility>

namespace rotafab::jobs::nesting {
namespace {

using ClipperLib::IntPoint;
using ClipperLib::Path;
using Wide = __int128;  // cross products of grid coordinates overflow 64 bits only on absurd inputs; never here

Wide cross(const IntPoint& o, const IntPoint& a, const IntPoint& b) {
  return static_cast<Wide>(a.X - o.X) * (b.Y - o.Y) - static_cast<Wide>(a.Y - o.Y) * (b.X - o.X);
}

bool same(const IntPoint& a, const IntPoint& b) { return a.X == b.X && a.Y == b.Y; }

// Whether `p` lies in the closed counter-clockwise triangle (a, b, c).
bool inTriangle(const IntPoint& p, const IntPoint& a, const IntPoint& b, const IntPoint& c) {
  return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
}

// Whether the corner prev -> at -> next turns left or goes straight on.
bool convexCorner(const IntPoint& prev, const IntPoint& at, const IntPoint& next) {
  const Wide turn = cross(prev, at, next);
  if (turn != 0) return turn > 0;
  // Collinear: straight on is convex, doubling back is not.
  return static_cast<Wide>(at.X - prev.X) * (next.X - at.X) + static_cast<Wide>(at.Y - prev.Y) * (next.Y - at.Y) > 0;
}

// Ear clipping over vertex indices; triangles counter-clockwise.
std::optional<std::vector<std::vector<int>>> triangulate(const Path& points) {
  const int n = static_cast<int>(points.size());
  std::vector<int> next(n), prev(n);
  for (int i = 0; i < n; ++i) next[i] = (i + 1) % n, prev[i] = (i + n - 1) % n;
  std::vector<std::vector<int>> triangles;
  int remaining = n, at = 0, sinceLastEar = 0;
  while (remaining > 3) {
    if (sinceLastEar > remaining) return std::nullopt;  // a full turn without an ear: not simple
    const int p = prev[at], q = next[at];
    const Wide turn = cross(points[p], points[at], points[q]);
    bool ear = turn > 0;
    if (turn == 0) {
      // A straight corner or a needle: dropping the vertex changes no area.
      ear = true;
    } else if (ear) {
      for (int v = next[q]; v != p; v = next[v]) {
        const IntPoint& r = points[v];
        if (same(r, points[p]) || same(r, points[at]) || same(r, points[q])) continue;
        if (inTriangle(r, points[p], points[at], points[q])) {
          ear = false;
          break;
        }
      }
    }
    if (!ear) {
      at = q;
      ++sinceLastEar;
      continue;
    }
    if (turn > 0) triangles.push_back({p, at, q});
    next[p] = q, prev[q] = p;
    --remaining;
    at = p;  // the corner at p changed; look at it again
    sinceLastEar = 0;
  }
  const int q = next[at], p = prev[at];
  if (cross(points[p], points[at], points[q]) > 0) triangles.push_back({p, at, q});
  return triangles;
}

bool convexPiece(const Path& points, const std::vector<int>& piece) {
  const size_t n = piece.size();
  for (size_t i = 0; i < n; ++i) {
    if (!convexCorner(points[piece[(i + n - 1) % n]], points[piece[i]], points[piece[(i + 1) % n]])) return false;
  }
  return true;
}

// The union of two pieces that share the edge a -> b (in `first`) / b -> a (in `second`).
std::vector<int> joined(const std::vector<int>& first, size_t edgeInFirst, const std::vector<int>& second,
                        size_t edgeInSecond) {
  std::vector<int> out;
  const size_t n = first.size(), m = second.size();
  for (size_t k = 1; k <= n; ++k) out.push_back(first[(edgeInFirst + k) % n]);   // b ... a
  for (size_t k = 2; k < m; ++k) out.push_back(second[(edgeInSecond + k) % m]);  // after a ... before b
  return out;
}

}  // namespace

std::optional<std::vector<Path>> convexPieces(const Path& polygon) {
  Path points;
  for (const IntPoint& p : polygon) {
    if (points.empty() || !same(points.back(), p)) points.push_back(p);
  }
  while (points.size() > 1 && same(points.front(), points.back())) points.pop_back();
  if (points.size() < 3) return std::nullopt;
  if (ClipperLib::Area(points) < 0) std::reverse(points.begin(), points.end());
  auto triangles = triangulate(points);
  if (!triangles || triangles->empty()) return std::nullopt;
  // Hertel-Mehlhorn: drop a diagonal whenever both pieces beside it merge convex.
  std::vector<std::vector<int>> pieces = std::move(*triangles);
  bool merged = true;
  while (merged) {
    merged = false;
    std::map<std::pair<int, int>, std::pair<size_t, size_t>> edges;  // (from, to) -> (piece, position)
    for (size_t i = 0; i < pieces.size(); ++i) {
      for (size_t k = 0; k < pieces[i].size(); ++k) {
        edges[{pieces[i][k], pieces[i][(k + 1) % pieces[i].size()]}] = {i, k};
      }
    }
    for (size_t i = 0; i < pieces.size() && !merged; ++i) {
      for (size_t k = 0; k < pieces[i].size() && !merged; ++k) {
        const int a = pieces[i][k], b = pieces[i][(k + 1) % pieces[i].size()];
        const auto twin = edges.find({b, a});
        if (twin == edges.end() || twin->second.first == i) continue;
        const auto [j, position] = twin->second;
        std::vector<int> candidate = joined(pieces[i], k, pieces[j], position);
        if (!convexPiece(points, candidate)) continue;
        pieces[i] = std::move(candidate);
        pieces.erase(pieces.begin() + static_cast<long>(j));
        merged = true;
      }
    }
  }
  std::vector<Path> out;
  for (const auto& piece : pieces) {
    Path path;
    for (size_t k = 0; k < piece.size(); ++k) {
      const IntPoint& before = points[piece[(k + piece.size() - 1) % piece.size()]];
      const IntPoint& after = points[piece[(k + 1) % piece.size()]];
      if (cross(before, points[piece[k]], after) != 0) path.push_back(points[piece[k]]);  // drop straight corners
    }
    if (path.size() >= 3) out.push_back(std::move(path));
  }
  return out;
}

Path convexMinkowskiSum(const Path& a, const Path& b) {
  // Both start at their lowest (then leftmost) vertex; the edges then come in
  // increasing angle from 0 to 2 pi in each, and merging them walks the sum.
  auto lowest = [](const Path& p) {
    size_t best = 0;
    for (size_t i = 1; i < p.size(); ++i) {
      if (p[i].Y < p[best].Y || (p[i].Y == p[best].Y && p[i].X < p[best].X)) best = i;
    }
    return best;
  };
  const size_t n = a.size(), m = b.size(), startA = lowest(a), startB = lowest(b);
  Path sum;
  sum.reserve(n + m);
  size_t i = 0, j = 0;
  while (i < n || j < m) {
    const IntPoint& pa = a[(startA + i) % n];
    const IntPoint& pb = b[(startB + j) % m];
    sum.push_back({pa.X + pb.X, pa.Y + pb.Y});
    if (i == n) {
      ++j;
      continue;
    }
    if (j == m) {
      ++i;
      continue;
    }
    const IntPoint& na = a[(startA + i + 1) % n];
    const IntPoint& nb = b[(startB + j + 1) % m];
    const Wide turn = static_cast<Wide>(na.X - pa.X) * (nb.Y - pb.Y) - static_cast<Wide>(na.Y - pa.Y) * (nb.X - pb.X);
    if (turn >= 0) ++i;
    if (turn <= 0) ++j;
  }
  return sum;
}

}  // namespace rotafab::jobs::nesting
