#include "geometry/RibbonCollisions.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>

namespace rotafab::geometry {
namespace {

using Triangle = std::array<Point3, 3>;

// Whether the segment ab passes through the inside of triangle t (touching
// at a corner or along a side does not count: the strips' own neighbours
// share those).
bool segmentThrough(const Point3& a, const Point3& b, const Triangle& t) {
  constexpr double kInside = 1e-9;
  const Point3 d = b - a, e1 = t[1] - t[0], e2 = t[2] - t[0];
  const Point3 p = d.cross(e2);
  const double det = e1.dot(p);
  // A segment in the triangle's plane (or nearly: flat parts of one strip
  // are coplanar, and rounding grows with the coordinates) does not pass
  // through it.
  if (std::abs(det) <= 1e-9 * d.norm() * e1.norm() * e2.norm()) return false;
  const Point3 s = a - t[0];
  const double u = s.dot(p) / det;
  if (u < kInside || u > 1 - kInside) return false;
  const Point3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < kInside || u + v > 1 - kInside) return false;
  const double along = e2.dot(q) / det;
  return along > kInside && along < 1 - kInside;
}

// Whether all of `t` lies strictly on one side of the plane of `of`.
bool oneSide(const Triangle& of, const Triangle& t) {
  const Point3 normal = (of[1] - of[0]).cross(of[2] - of[0]);
  const double d0 = normal.dot(t[0] - of[0]), d1 = normal.dot(t[1] - of[0]), d2 = normal.dot(t[2] - of[0]);
  return (d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0);
}

// Two triangles not in one plane meet where a side of one passes through
// the other; not if either lies on one side of the other's plane (the
// strands of a crossing, 2h apart, are most of the pairs tested).
bool trianglesMeet(const Triangle& a, const Triangle& b) {
  if (oneSide(a, b) || oneSide(b, a)) return false;
  for (int i = 0; i < 3; ++i) {
    if (segmentThrough(a[i], a[(i + 1) % 3], b) || segmentThrough(b[i], b[(i + 1) % 3], a)) return true;
  }
  return false;
}

// The two triangles of the strip's quad `quad` between rows quad and quad + 1.
std::array<Triangle, 2> quadTriangles(const std::vector<Point3>& p, const std::vector<Point3>& q, size_t quad) {
  const size_t next = (quad + 1) % p.size();
  return {Triangle{p[quad], q[quad], p[next]}, Triangle{q[quad], q[next], p[next]}};
}

struct Box {
  Point3 low, high;
  [[nodiscard]] bool apart(const Box& other) const {
    return (high.array() < other.low.array()).any() || (other.high.array() < low.array()).any();
  }
};

// The box of the strip's quad between rows i and i + 1 (mod the rows).
Box quadBox(const std::vector<Point3>& p, const std::vector<Point3>& q, size_t i) {
  const size_t next = (i + 1) % p.size();
  return {p[i].cwiseMin(q[i]).cwiseMin(p[next]).cwiseMin(q[next]),
          p[i].cwiseMax(q[i]).cwiseMax(p[next]).cwiseMax(q[next])};
}

// Whether all four corners of a quad lie strictly on one side of a plane.
bool quadOnOneSide(const Point3& origin, const Point3& normal, const std::array<Point3, 4>& quad) {
  int above = 0, below = 0;
  for (const Point3& p : quad) {
    const double d = normal.dot(p - origin);
    above += d > 0 ? 1 : 0;
    below += d < 0 ? 1 : 0;
  }
  return above == 4 || below == 4;
}

bool quadsMeet(const std::vector<Point3>& pa, const std::vector<Point3>& qa, size_t i, const std::vector<Point3>& pb,
               const std::vector<Point3>& qb, size_t j) {
  const std::array<Triangle, 2> as = quadTriangles(pa, qa, i), bs = quadTriangles(pb, qb, j);
  // Most quads tested lie one over the other at a crossing: one plane test
  // per triangle for the whole of the other quad first.
  const size_t ni = (i + 1) % pa.size(), nj = (j + 1) % pb.size();
  const std::array<Point3, 4> quadB{pb[j], qb[j], pb[nj], qb[nj]};
  const std::array<Point3, 4> quadA{pa[i], qa[i], pa[ni], qa[ni]};
  const auto clearOf = [](const Triangle& t, const std::array<Point3, 4>& quad) {
    return quadOnOneSide(t[0], (t[1] - t[0]).cross(t[2] - t[0]), quad);
  };
  const bool aClear[2] = {clearOf(as[0], quadB), clearOf(as[1], quadB)};
  if (aClear[0] && aClear[1]) return false;
  const bool bClear[2] = {clearOf(bs[0], quadA), clearOf(bs[1], quadA)};
  if (bClear[0] && bClear[1]) return false;
  for (size_t x = 0; x < 2; ++x) {
    for (size_t y = 0; y < 2; ++y) {
      if (!aClear[x] && !bClear[y] && trianglesMeet(as[x], bs[y])) return true;
    }
  }
  return false;
}

// A strip's own quads within this many rows of each other touch or nearly
// (a sharp fold there is the unfolding's to find): not tested.
constexpr int kOwnRowsApart = 3;
bool ownNeighbours(int rowA, int rowB, int rows) {
  const int apart = std::abs(rowA - rowB) % rows;
  return std::min(apart, rows - apart) <= kOwnRowsApart;
}

// Whether two pieces of strip meet: rows `pa`, `qa` from strip row `firstA`
// on, `pb`, `qb` from `firstB`; `rows` the strip's rows when both are of one
// strip, else 0.
bool stripsMeet(const std::vector<Point3>& pa, const std::vector<Point3>& qa, int firstA, const std::vector<Point3>& pb,
                const std::vector<Point3>& qb, int firstB, int rows) {
  std::vector<Box> boxes;
  for (size_t j = 0; j + 1 < pb.size(); ++j) boxes.push_back(quadBox(pb, qb, j));
  for (size_t i = 0; i + 1 < pa.size(); ++i) {
    const Box box = quadBox(pa, qa, i);
    for (size_t j = 0; j + 1 < pb.size(); ++j) {
      if (rows > 0 && ownNeighbours(firstA + static_cast<int>(i), firstB + static_cast<int>(j), rows)) continue;
      if (!box.apart(boxes[j]) && quadsMeet(pa, qa, i, pb, qb, j)) return true;
    }
  }
  return false;
}

struct Quad {
  int ribbon = 0, index = 0;  // the strip's quad between rows index and index + 1
  Box box;
};

// The pairs of ribbon segments, (ribbon, segment) each, whose strips meet,
// each with the first two of their quads that do (strip rows, in the
// pair's order): every quad in the cells of a uniform grid its box covers,
// and the quads that share a cell tested against each other, once, in the
// first cell their boxes share.
using Segment = std::pair<int, int>;
using Meetings = std::map<std::pair<Segment, Segment>, std::pair<int, int>>;
using Found = std::pair<std::pair<Segment, Segment>, std::pair<int, int>>;

// Meetings found in parts, each pair with its first rows.
Meetings merged(const std::vector<std::vector<Found>>& parts) {
  Meetings meeting;
  for (const std::vector<Found>& found : parts) {
    for (const auto& [pair, rows] : found) {
      const auto [at, added] = meeting.emplace(pair, rows);
      if (!added) at->second = std::min(at->second, rows);
    }
  }
  return meeting;
}

Meetings meetingSegments(const std::vector<Ribbon>& ribbons, const core::WorkContext& context) {
  std::vector<Quad> quads;
  double extent = 0;
  for (size_t r = 0; r < ribbons.size(); ++r) {
    const Ribbon& ribbon = ribbons[r];
    for (size_t i = 0; i < ribbon.railP.size(); ++i) {
      const Quad quad{static_cast<int>(r), static_cast<int>(i), quadBox(ribbon.railP, ribbon.railQ, i)};
      extent += (quad.box.high - quad.box.low).maxCoeff();
      quads.push_back(quad);
    }
  }
  if (quads.empty()) return {};
  // Cells about twice as large as a quad: each quad in a few of them
  // (smaller cells, more entries, were slower on 50 000 faces).
  const double cell = std::max(2 * extent / static_cast<double>(quads.size()), 1e-9);
  const auto cellOf = [cell](double x) { return static_cast<std::int64_t>(std::floor(x / cell)); };
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    constexpr std::int64_t kMask = (std::int64_t{1} << 21) - 1;
    return static_cast<std::uint64_t>(((x & kMask) << 42) | ((y & kMask) << 21) | (z & kMask));
  };
  std::vector<std::pair<std::uint64_t, int>> entries;
  for (size_t k = 0; k < quads.size(); ++k) {
    const Quad& quad = quads[k];
    for (auto x = cellOf(quad.box.low.x()); x <= cellOf(quad.box.high.x()); ++x) {
      for (auto y = cellOf(quad.box.low.y()); y <= cellOf(quad.box.high.y()); ++y) {
        for (auto z = cellOf(quad.box.low.z()); z <= cellOf(quad.box.high.z()); ++z) {
          entries.emplace_back(key(x, y, z), static_cast<int>(k));
        }
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  std::vector<size_t> starts;
  for (size_t i = 0; i < entries.size(); ++i) {
    if (i == 0 || entries[i].first != entries[i - 1].first) starts.push_back(i);
  }
  starts.push_back(entries.size());
  context.check();

  // Found cell by cell, merged after: no lock while testing.
  std::vector<std::vector<Found>> foundInCell(starts.size() - 1);
  // The quads cell by cell, in one array: read in order while testing.
  std::vector<Quad> inCells;
  inCells.reserve(entries.size());
  for (const auto& entry : entries) inCells.push_back(quads[static_cast<size_t>(entry.second)]);
  context.parallelFor(starts.size() - 1, [&](size_t c) {
    // Sorted along x in the cell, a quad is tested only against those
    // after it that begin before it ends (sweep and prune).
    std::sort(inCells.begin() + static_cast<std::ptrdiff_t>(starts[c]),
              inCells.begin() + static_cast<std::ptrdiff_t>(starts[c + 1]),
              [](const Quad& a, const Quad& b) { return a.box.low.x() < b.box.low.x(); });
    for (size_t i = starts[c]; i < starts[c + 1]; ++i) {
      const Quad& a = inCells[i];
      for (size_t j = i + 1; j < starts[c + 1] && inCells[j].box.low.x() <= a.box.high.x(); ++j) {
        const Quad& b = inCells[j];
        if (a.box.apart(b.box)) continue;
        const Ribbon& ra = ribbons[static_cast<size_t>(a.ribbon)];
        const Ribbon& rb = ribbons[static_cast<size_t>(b.ribbon)];
        if (a.ribbon == b.ribbon && ownNeighbours(a.index, b.index, static_cast<int>(ra.railP.size()))) continue;
        // Tested once, in the first cell the two boxes share.
        const Point3 shared = a.box.low.cwiseMax(b.box.low);
        if (key(cellOf(shared.x()), cellOf(shared.y()), cellOf(shared.z())) != entries[i].first) continue;
        if (!quadsMeet(ra.railP, ra.railQ, static_cast<size_t>(a.index), rb.railP, rb.railQ,
                       static_cast<size_t>(b.index))) {
          continue;
        }
        Segment sa{a.ribbon, a.index / ra.samples}, sb{b.ribbon, b.index / rb.samples};
        std::pair<int, int> rows{a.index, b.index};
        if (sb < sa) {
          std::swap(sa, sb);
          std::swap(rows.first, rows.second);
        }
        foundInCell[c].push_back({{sa, sb}, rows});
      }
    }
  });
  return merged(foundInCell);
}

// The pairs of segments that meet among those that turn about one corner:
// a vertex, or a face's centre (each segment turns about one of each, its
// pass's `to`). Where few regions meet at a corner, wide ribbons cut across
// it (eq. 4.17's cubic) into each other's way: nearly every meeting is
// there, and these are a few pairs per corner instead of every quad near
// another. Not a strip against its own.
Meetings cornerMeetings(const std::vector<Ribbon>& ribbons, const core::WorkContext& context) {
  int vertices = 0, faces = 0;
  for (const Ribbon& ribbon : ribbons) {
    for (const RibbonPass& pass : ribbon.passes) {
      vertices = std::max(vertices, pass.to.vertex + 1);
      faces = std::max(faces, pass.to.face + 1);
    }
  }
  std::vector<std::vector<Segment>> about(static_cast<size_t>(vertices + faces));
  for (size_t r = 0; r < ribbons.size(); ++r) {
    for (size_t k = 0; k < ribbons[r].passes.size(); ++k) {
      const FaceCorner& corner = ribbons[r].passes[k].to;
      const Segment segment{static_cast<int>(r), static_cast<int>(k)};
      about[static_cast<size_t>(corner.vertex)].push_back(segment);
      about[static_cast<size_t>(vertices + corner.face)].push_back(segment);
    }
  }
  std::vector<std::vector<Found>> foundAt(about.size());
  context.parallelFor(about.size(), [&](size_t c) {
    const std::vector<Segment>& segments = about[c];
    for (size_t x = 0; x < segments.size(); ++x) {
      for (size_t y = x + 1; y < segments.size(); ++y) {
        Segment sa = segments[x], sb = segments[y];
        if (sa.first == sb.first) continue;
        if (sb < sa) std::swap(sa, sb);
        const Ribbon& ra = ribbons[static_cast<size_t>(sa.first)];
        const Ribbon& rb = ribbons[static_cast<size_t>(sb.first)];
        bool met = false;
        for (int i = sa.second * ra.samples; !met && i < (sa.second + 1) * ra.samples; ++i) {
          const Box box = quadBox(ra.railP, ra.railQ, static_cast<size_t>(i));
          for (int j = sb.second * rb.samples; !met && j < (sb.second + 1) * rb.samples; ++j) {
            if (box.apart(quadBox(rb.railP, rb.railQ, static_cast<size_t>(j)))) continue;
            if (quadsMeet(ra.railP, ra.railQ, static_cast<size_t>(i), rb.railP, rb.railQ, static_cast<size_t>(j))) {
              foundAt[c].push_back({{sa, sb}, {i, j}});
              met = true;
            }
          }
        }
      }
    }
  });
  return merged(foundAt);
}

// Per pair of meeting segments, the widest width at which the two alone,
// made again with it at all their passes, do not meet, by `bisections`
// bisections between `least` and the shape's width (`least` when none
// tried clears them).
std::vector<double> pairClearWidths(const RotationSystem& rs, const WeaveThreads& weave,
                                    const std::vector<EdgeRegion>& regions, const std::vector<Ribbon>& ribbons,
                                    const RibbonShape& shape, const std::vector<std::pair<Segment, Segment>>& pairs,
                                    double least, int bisections, const core::WorkContext& context) {
  std::vector<double> clear(pairs.size(), 0);
  context.parallelFor(pairs.size(), [&](size_t i) {
    const auto& [sa, sb] = pairs[i];
    const Thread& ta = weave.threads[static_cast<size_t>(sa.first)];
    const Thread& tb = weave.threads[static_cast<size_t>(sb.first)];
    RibbonShape trial = shape;
    double low = least, high = shape.width;
    std::vector<Point3> pa, qa, pb, qb;
    for (int k = 0; k < bisections; ++k) {
      trial.width = (low + high) / 2;
      segmentRows(rs, regions, ta, ribbons[static_cast<size_t>(sa.first)], sa.second, trial, pa, qa);
      segmentRows(rs, regions, tb, ribbons[static_cast<size_t>(sb.first)], sb.second, trial, pb, qb);
      const Ribbon& ra = ribbons[static_cast<size_t>(sa.first)];
      const int rows = sa.first == sb.first ? static_cast<int>(ra.railP.size()) : 0;
      (stripsMeet(pa, qa, sa.second * ra.samples, pb, qb, sb.second * ra.samples, rows) ? high : low) = trial.width;
    }
    clear[i] = low;
  });
  return clear;
}

// The mesh edges of a segment's two passes.
std::array<int, 2> segmentEdges(const std::vector<Ribbon>& ribbons, const Segment& segment) {
  const Ribbon& ribbon = ribbons[static_cast<size_t>(segment.first)];
  const size_t n = ribbon.passes.size(), k = static_cast<size_t>(segment.second);
  return {ribbon.passes[k % n].edge, ribbon.passes[(k + 1) % n].edge};
}

// The edge of the pass nearer a segment's quad (strip row `row`).
int edgeNearest(const std::vector<Ribbon>& ribbons, const Segment& segment, int row) {
  const int samples = ribbons[static_cast<size_t>(segment.first)].samples;
  return segmentEdges(ribbons, segment)[2 * (row % samples) < samples ? 0 : 1];
}

std::vector<std::pair<Segment, Segment>> pairsOf(const Meetings& meeting) {
  std::vector<std::pair<Segment, Segment>> pairs;
  pairs.reserve(meeting.size());
  for (const auto& [pair, rows] : meeting) pairs.push_back(pair);
  return pairs;
}

}  // namespace

RibbonCollisions ribbonCollisions(const RotationSystem& rs, const WeaveThreads& weave,
                                  const std::vector<EdgeRegion>& regions, const std::vector<Ribbon>& ribbons,
                                  const RibbonShape& shape, const core::WorkContext& context) {
  const Meetings meeting = meetingSegments(ribbons, context);
  context.check();
  RibbonCollisions result;
  if (meeting.empty()) return result;
  // Per pair of segments, the widest width at which they do not meet; named
  // by the edges of their passes nearest where they meet.
  std::map<std::pair<int, int>, double> clearOfEdges;
  const std::vector<std::pair<Segment, Segment>> pairs = pairsOf(meeting);
  // To a thousandth of the widest, as the warning gives it.
  constexpr int kBisections = 10;
  const std::vector<double> clear = pairClearWidths(rs, weave, regions, ribbons, shape, pairs, 0, kBisections, context);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const std::pair<int, int>& rows = meeting.at(pairs[i]);
    const int a = edgeNearest(ribbons, pairs[i].first, rows.first);
    const int b = edgeNearest(ribbons, pairs[i].second, rows.second);
    const std::pair<int, int> edges{std::min(a, b), std::max(a, b)};
    const auto at = clearOfEdges.find(edges);
    clearOfEdges[edges] = at == clearOfEdges.end() ? clear[i] : std::min(at->second, clear[i]);
  }
  for (const auto& [edges, width] : clearOfEdges) result.pairs.push_back({edges.first, edges.second, width});
  // Narrower ribbons move every crossing's quad, so other segments may meet
  // at the width that clears these: the whole weave made again at it and
  // looked at once more, a little narrower each time, a few times at most.
  double width = shape.width;
  for (const RibbonCollision& pair : result.pairs) width = std::min(width, pair.clearWidth);
  constexpr int kRounds = 4;
  for (int round = 0; round < kRounds && width > 0; ++round, width *= 0.75) {
    RibbonShape trial = shape;
    trial.width = width;
    if (meetingSegments(weaveRibbons(rs, weave, regions, trial), context).empty()) {
      result.clearWidth = width;
      break;
    }
  }
  return result;
}

ClearedRibbons narrowUntilClear(const RotationSystem& rs, const WeaveThreads& weave,
                                const std::vector<EdgeRegion>& regions, const RibbonShape& shape,
                                const core::WorkContext& context) {
  ClearedRibbons result;
  result.edgeWidths.assign(regions.size(), shape.width);
  constexpr int kRounds = 6;
  // Where the width a pair clears at is not less than its passes have (their
  // widths differ along the segments), a tenth less each round.
  constexpr double kStep = 0.9, kNoLess = 0.98;
  // Not to nothing: a pair no width clears (faces folded sharply onto each
  // other) is left to the warning.
  const double narrowest = narrowestUsefulWidth(shape);
  for (int round = 0;; ++round) {
    result.ribbons = weaveRibbons(rs, weave, regions, shape, result.edgeWidths);
    // First about each corner, where nearly all meet; every round after,
    // and the check that ends them, everywhere.
    Meetings meeting = round == 0 ? cornerMeetings(result.ribbons, context) : Meetings{};
    if (meeting.empty()) meeting = meetingSegments(result.ribbons, context);
    context.check();
    if (meeting.empty()) break;
    if (round == kRounds) {
      result.left = ribbonCollisions(rs, weave, regions, result.ribbons, shape, context);
      break;
    }
    const std::vector<std::pair<Segment, Segment>> pairs = pairsOf(meeting);
    // To 3/64 of the widest, from the narrowest allowed: what is left is
    // checked again.
    constexpr int kBisections = 4;
    const std::vector<double> clear =
        pairClearWidths(rs, weave, regions, result.ribbons, shape, pairs, narrowest, kBisections, context);
    std::vector<double> widths = result.edgeWidths;
    for (size_t i = 0; i < pairs.size(); ++i) {
      for (const Segment& segment : {pairs[i].first, pairs[i].second}) {
        for (const int edge : segmentEdges(result.ribbons, segment)) {
          const double had = result.edgeWidths[static_cast<size_t>(edge)];
          double& width = widths[static_cast<size_t>(edge)];
          width = std::max(narrowest, std::min(width, clear[i] < kNoLess * had ? clear[i] : kStep * had));
        }
      }
    }
    result.edgeWidths = std::move(widths);
  }
  result.narrowed = static_cast<int>(
      std::count_if(result.edgeWidths.begin(), result.edgeWidths.end(), [&](double w) { return w < shape.width; }));
  return result;
}

}  // namespace rotafab::geometry
