#include "geometry/RibbonCollisions.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <set>
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
  if (std::abs(det) < 1e-300) return false;
  const Point3 s = a - t[0];
  const double u = s.dot(p) / det;
  if (u < kInside || u > 1 - kInside) return false;
  const Point3 q = s.cross(e1);
  const double v = d.dot(q) / det;
  if (v < kInside || u + v > 1 - kInside) return false;
  const double along = e2.dot(q) / det;
  return along > kInside && along < 1 - kInside;
}

// Two triangles not in one plane meet where a side of one passes through the other.
bool trianglesMeet(const Triangle& a, const Triangle& b) {
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

bool stripsMeet(const std::vector<Point3>& pa, const std::vector<Point3>& qa, const std::vector<Point3>& pb,
                const std::vector<Point3>& qb) {
  for (size_t i = 0; i + 1 < pa.size(); ++i) {
    for (const Triangle& a : quadTriangles(pa, qa, i)) {
      for (size_t j = 0; j + 1 < pb.size(); ++j) {
        for (const Triangle& b : quadTriangles(pb, qb, j)) {
          if (trianglesMeet(a, b)) return true;
        }
      }
    }
  }
  return false;
}

struct Quad {
  int ribbon = 0, index = 0;  // the strip's quad between rows index and index + 1
  Point3 low, high;           // its box
};

// The edges of the two passes a quad's segment runs between.
std::pair<int, int> segmentEdges(const Ribbon& ribbon, int index) {
  const size_t passes = ribbon.passes.size();
  const size_t k = static_cast<size_t>(index / ribbon.samples);
  return {ribbon.passes[k % passes].edge, ribbon.passes[(k + 1) % passes].edge};
}

// The pairs of ribbon segments, (ribbon, segment) each, whose strips meet:
// every quad in the cells of a uniform grid its box covers, and the quads
// that share a cell tested against each other, once, in the first cell
// their boxes share.
using Segment = std::pair<int, int>;
std::set<std::pair<Segment, Segment>> meetingSegments(const std::vector<Ribbon>& ribbons,
                                                      const core::WorkContext& context) {
  std::vector<Quad> quads;
  double extent = 0;
  for (size_t r = 0; r < ribbons.size(); ++r) {
    const Ribbon& ribbon = ribbons[r];
    for (size_t i = 0; i < ribbon.railP.size(); ++i) {
      const size_t next = (i + 1) % ribbon.railP.size();
      Quad quad{static_cast<int>(r), static_cast<int>(i), ribbon.railP[i], ribbon.railP[i]};
      for (const Point3* p : {&ribbon.railQ[i], &ribbon.railP[next], &ribbon.railQ[next]}) {
        quad.low = quad.low.cwiseMin(*p);
        quad.high = quad.high.cwiseMax(*p);
      }
      extent += (quad.high - quad.low).maxCoeff();
      quads.push_back(quad);
    }
  }
  if (quads.empty()) return {};
  // Cells about as large as a quad: each quad in a few of them.
  const double cell = std::max(extent / static_cast<double>(quads.size()), 1e-9);
  const auto cellOf = [cell](double x) { return static_cast<std::int64_t>(std::floor(x / cell)); };
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    constexpr std::int64_t kMask = (std::int64_t{1} << 21) - 1;
    return static_cast<std::uint64_t>(((x & kMask) << 42) | ((y & kMask) << 21) | (z & kMask));
  };
  std::vector<std::pair<std::uint64_t, int>> entries;
  for (size_t k = 0; k < quads.size(); ++k) {
    const Quad& quad = quads[k];
    for (auto x = cellOf(quad.low.x()); x <= cellOf(quad.high.x()); ++x) {
      for (auto y = cellOf(quad.low.y()); y <= cellOf(quad.high.y()); ++y) {
        for (auto z = cellOf(quad.low.z()); z <= cellOf(quad.high.z()); ++z) {
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

  std::set<std::pair<Segment, Segment>> meeting;
  std::mutex found;
  context.parallelFor(starts.size() - 1, [&](size_t c) {
    for (size_t i = starts[c]; i < starts[c + 1]; ++i) {
      const Quad& a = quads[static_cast<size_t>(entries[i].second)];
      const Ribbon& ra = ribbons[static_cast<size_t>(a.ribbon)];
      const int rows = static_cast<int>(ra.railP.size());
      for (size_t j = i + 1; j < starts[c + 1]; ++j) {
        const Quad& b = quads[static_cast<size_t>(entries[j].second)];
        const Ribbon& rb = ribbons[static_cast<size_t>(b.ribbon)];
        // A strip's neighbouring quads share their rows.
        if (a.ribbon == b.ribbon) {
          const int apart = std::abs(a.index - b.index);
          if (std::min(apart, rows - apart) <= 1) continue;
        }
        if ((a.high.array() < b.low.array()).any() || (b.high.array() < a.low.array()).any()) continue;
        // Ribbons pushing against their neighbours is what ch. VII means:
        // two ribbons that cross at an edge lie one on the other there by
        // design (the over one h above the surface, the under one h below,
        // touching as the paper bends either side), so segments that run
        // to or from one crossing are not tested against each other.
        const auto [a0, a1] = segmentEdges(ra, a.index);
        const auto [b0, b1] = segmentEdges(rb, b.index);
        if (a0 == b0 || a0 == b1 || a1 == b0 || a1 == b1) continue;
        // Tested once, in the first cell the two boxes share.
        const Point3 shared = a.low.cwiseMax(b.low);
        if (key(cellOf(shared.x()), cellOf(shared.y()), cellOf(shared.z())) != entries[i].first) continue;
        bool meet = false;
        for (const Triangle& ta : quadTriangles(ra.railP, ra.railQ, static_cast<size_t>(a.index))) {
          for (const Triangle& tb : quadTriangles(rb.railP, rb.railQ, static_cast<size_t>(b.index))) {
            meet = meet || trianglesMeet(ta, tb);
          }
        }
        if (!meet) continue;
        Segment sa{a.ribbon, a.index / ra.samples}, sb{b.ribbon, b.index / rb.samples};
        if (sb < sa) std::swap(sa, sb);
        const std::lock_guard lock(found);
        meeting.emplace(sa, sb);
      }
    }
  });
  return meeting;
}

}  // namespace

RibbonCollisions ribbonCollisions(const RotationSystem& rs, const WeaveThreads& weave,
                                  const std::vector<EdgeRegion>& regions, const std::vector<Ribbon>& ribbons,
                                  const RibbonShape& shape, const core::WorkContext& context) {
  const std::set<std::pair<Segment, Segment>> meeting = meetingSegments(ribbons, context);
  context.check();
  RibbonCollisions result;
  if (meeting.empty()) return result;
  // Per pair of segments, the widest width at which they do not meet, by
  // bisection, the two segments made again at each width; named by the
  // edges of their passes nearest the meeting (their first).
  std::map<std::pair<int, int>, double> clearOfEdges;
  const std::vector<std::pair<Segment, Segment>> pairs(meeting.begin(), meeting.end());
  std::vector<double> clear(pairs.size(), 0);
  context.parallelFor(pairs.size(), [&](size_t i) {
    const auto& [sa, sb] = pairs[i];
    const Thread& ta = weave.threads[static_cast<size_t>(sa.first)];
    const Thread& tb = weave.threads[static_cast<size_t>(sb.first)];
    RibbonShape trial = shape;
    double low = 0, high = shape.width;
    std::vector<Point3> pa, qa, pb, qb;
    constexpr int kBisections = 10;
    for (int k = 0; k < kBisections; ++k) {
      trial.width = (low + high) / 2;
      segmentRows(rs, regions, ta, ribbons[static_cast<size_t>(sa.first)], sa.second, trial, pa, qa);
      segmentRows(rs, regions, tb, ribbons[static_cast<size_t>(sb.first)], sb.second, trial, pb, qb);
      (stripsMeet(pa, qa, pb, qb) ? high : low) = trial.width;
    }
    clear[i] = low;
  });
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto& [sa, sb] = pairs[i];
    const auto edgeOf = [&](const Segment& s) {
      const Ribbon& ribbon = ribbons[static_cast<size_t>(s.first)];
      return ribbon.passes[static_cast<size_t>(s.second) % ribbon.passes.size()].edge;
    };
    const int a = edgeOf(sa), b = edgeOf(sb);
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

}  // namespace rotafab::geometry
