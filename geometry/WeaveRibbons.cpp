#include "geometry/WeaveRibbons.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace rotafab::geometry {
namespace {

void requireShape(const RibbonShape& shape) {
  const auto fraction = [](double value, const char* name) {
    if (!(value > 0 && value <= 1)) {
      throw std::invalid_argument(
          fmt::format("{} {} is out of range: it must be more than 0 and at most 1", name, value));
    }
  };
  fraction(shape.width, "width");
  fraction(shape.curve, "curve");
  if (!(shape.offset > 0) || !std::isfinite(shape.offset)) {
    throw std::invalid_argument(fmt::format("offset {} is out of range: it must be more than 0", shape.offset));
  }
  if (shape.samples < 1) {
    throw std::invalid_argument(fmt::format("samples {} is out of range: at least 1", shape.samples));
  }
}

// The pass of `step` with its sides as rails P and Q, at its edge's width
// when `edgeWidths` gives one.
RibbonPass railPass(const RotationSystem& rs, const std::vector<EdgeRegion>& regions, const ThreadStep& step,
                    RibbonShape shape, bool swapped, const std::vector<double>& edgeWidths = {}) {
  const auto edge = static_cast<size_t>(RotationSystem::edgeOf(step.dart));
  if (!edgeWidths.empty()) shape.width = edgeWidths[edge];
  RibbonPass pass = ribbonPass(rs, regions[edge], step, shape);
  if (swapped) {
    std::swap(pass.head[0], pass.head[1]);
    std::swap(pass.middle[0], pass.middle[1]);
    std::swap(pass.tail[0], pass.tail[1]);
  }
  return pass;
}

}  // namespace

RibbonPass ribbonPass(const RotationSystem& rs, const EdgeRegion& region, const ThreadStep& step,
                      const RibbonShape& shape) {
  const Dart d = step.dart;
  const int e = RotationSystem::edgeOf(d);
  const bool forward = d == 2 * e;  // the dart runs from the region's start to its end
  RibbonPass pass;
  pass.edge = e;
  pass.crossing = step.crossing;
  const int fromFace = step.traceType == 0 ? rs.face(d) : rs.face(RotationSystem::reverse(d));
  const int otherFace = step.traceType == 0 ? rs.face(RotationSystem::reverse(d)) : rs.face(d);
  pass.from = {fromFace, rs.origin(d)};
  pass.to = {step.crossing == Crossing::None ? fromFace : otherFace, rs.target(d)};

  // The pass's own coordinates: a along the thread (0 at its head), b across
  // (0 on the vertex side at the head). The over strand runs along s of the
  // region's map X(s, u), from the start's corner in the left face to the
  // end's in the right; the under strand along u, from the start's corner in
  // the right face to the end's in the left (docs/WEAVE.md, 1.1 item 5, 1.5).
  // A dart against the region's direction runs them backwards, and its
  // vertex side at the head is the region's end.
  const Point3 lift = shape.offset * region.normal;
  // Beside an untwisted edge the thread runs in the half of the region in
  // its face: the triangle of the edge and that face's projected centre, a
  // degenerate bilinear quad whose ends are the two half-segments vertex to
  // centre, as a twisted pass's are (docs/WEAVE.md, section 4).
  const Point3& centre = fromFace == rs.face(2 * e) ? region.leftCentre : region.rightCentre;
  const Point3& origin = forward ? region.start : region.end;
  const Point3& target = forward ? region.end : region.start;
  const auto plain = [&](double a, double b) -> Point3 {
    switch (step.crossing) {
      case Crossing::Up:
        return forward ? region.at(a, b) : region.at(1 - a, 1 - b);
      case Crossing::Down:
        return forward ? region.at(b, a) : region.at(1 - b, 1 - a);
      case Crossing::None:
        break;
    }
    return (1 - b) * ((1 - a) * origin + a * target) + b * centre;
  };
  pass.lift = step.crossing == Crossing::Up ? lift : step.crossing == Crossing::Down ? Point3(-lift) : Point3::Zero();
  const double b0 = (1 - shape.width) / 2, b1 = (1 + shape.width) / 2;
  const double a0 = (1 - shape.curve) / 2, a1 = (1 + shape.curve) / 2;
  pass.head = {plain(a0, b0) + pass.lift, plain(a0, b1) + pass.lift};
  pass.middle = {plain(0.5, b0) + pass.lift, plain(0.5, b1) + pass.lift};
  pass.tail = {plain(a1, b0) + pass.lift, plain(a1, b1) + pass.lift};
  if (step.crossing != Crossing::None) {
    // The other strand runs across this one between a = b0 and a = b1 (the
    // region's map transposed): its rails, as lines in the plane.
    pass.planePoint = region.midpoint;
    pass.planeNormal = region.normal;
    // Each normal points away from the other strand's middle, which lies
    // strictly between its rails at any width (at width 1 the rails are
    // the region's sides).
    const Point3 inside = plain(0.5, 0.5);
    const auto awayFrom = [&](double a, Point3& point, Point3& normal) {
      point = plain(a, 0);
      normal = region.normal.cross(plain(a, 1) - point);
      if ((inside - point).dot(normal) > 0) normal = -normal;
      normal.normalize();
    };
    awayFrom(b0, pass.entryPoint, pass.entryNormal);
    awayFrom(b1, pass.exitPoint, pass.exitNormal);
  }
  return pass;
}

Point3 bezierPoint(const std::array<Point3, 4>& control, double t) {
  const double s = 1 - t;
  return s * s * s * control[0] + 3 * s * s * t * control[1] + 3 * s * t * t * control[2] + t * t * t * control[3];
}

Point3 bezierDerivative(const std::array<Point3, 4>& control, double t) {
  const double s = 1 - t;
  return 3 * s * s * (control[1] - control[0]) + 6 * s * t * (control[2] - control[1]) +
         3 * t * t * (control[3] - control[2]);
}

namespace {

std::array<Point3, 4> projectedControls(const RibbonPass& here, const RibbonPass& next, size_t side) {
  return {here.middle[side] - here.lift, here.tail[side] - here.lift, next.head[side] - next.lift,
          next.middle[side] - next.lift};
}

// Whether both rails at t, as projected, lie on the outer side of a half-plane.
bool bothOutside(const std::array<std::array<Point3, 4>, 2>& rails, const Point3& point, const Point3& normal,
                 double t) {
  return (bezierPoint(rails[0], t) - point).dot(normal) >= 0 && (bezierPoint(rails[1], t) - point).dot(normal) >= 0;
}

// The t from which `outside` holds all the way to `to`, on a grid from
// `from` to `to`, refined by bisection; `from` when it holds everywhere.
template <typename Outside>
double firstOutside(double from, double to, const Outside& outside) {
  constexpr int kScan = 16, kBisections = 7;
  int last = kScan;
  while (last >= 0 && outside(from + (to - from) * last / kScan)) --last;
  if (last < 0) return from;
  if (last == kScan) return to;
  double inside = from + (to - from) * last / kScan, out = from + (to - from) * (last + 1) / kScan;
  for (int k = 0; k < kBisections; ++k) {
    const double t = (inside + out) / 2;
    (outside(t) ? out : inside) = t;
  }
  return out;
}

}  // namespace

SegmentTurn segmentTurn(const RibbonPass& here, const RibbonPass& next) {
  const std::array<std::array<Point3, 4>, 2> rails{projectedControls(here, next, 0), projectedControls(here, next, 1)};
  SegmentTurn turn;
  if (here.crossing != Crossing::None) {
    turn.leave = firstOutside(0, 1, [&](double t) { return bothOutside(rails, here.exitPoint, here.exitNormal, t); });
  }
  if (next.crossing != Crossing::None) {
    turn.arrive =
        firstOutside(1, 0, [&](double t) { return bothOutside(rails, next.entryPoint, next.entryNormal, t); });
  }
  if (turn.arrive - turn.leave < kLeastTurn) {
    const double middle = std::clamp((turn.leave + turn.arrive) / 2, kLeastTurn / 2, 1 - kLeastTurn / 2);
    turn = {middle - kLeastTurn / 2, middle + kLeastTurn / 2};
  }
  return turn;
}

Point3 segmentPoint(const RibbonPass& here, const RibbonPass& next, const SegmentTurn& turn, int side, double t) {
  const Point3 base = bezierPoint(projectedControls(here, next, static_cast<size_t>(side)), t);
  // Each end's plane and height, blended by a smoothstep over the turn (no
  // slope at either end of it).
  const double x = std::clamp((t - turn.leave) / (turn.arrive - turn.leave), 0.0, 1.0), rise = x * x * (3 - 2 * x);
  const auto onPlane = [&base](const RibbonPass& pass) {
    return pass.lift - (base - pass.planePoint).dot(pass.planeNormal) * pass.planeNormal;
  };
  return base + (1 - rise) * onPlane(here) + rise * onPlane(next);
}

std::array<Point3, 4> segmentControls(const Ribbon& ribbon, int pass, int side) {
  const int count = static_cast<int>(ribbon.passes.size());
  const RibbonPass& here = ribbon.passes[static_cast<size_t>(((pass % count) + count) % count)];
  const RibbonPass& next = ribbon.passes[static_cast<size_t>((((pass + 1) % count) + count) % count)];
  const auto s = static_cast<size_t>(side);
  return {here.middle[s], here.tail[s], next.head[s], next.middle[s]};
}

void segmentRows(const RotationSystem& rs, const std::vector<EdgeRegion>& regions, const Thread& thread,
                 const Ribbon& ribbon, int k, const RibbonShape& shape, std::vector<Point3>& railP,
                 std::vector<Point3>& railQ) {
  const size_t n = thread.steps.size();
  const size_t here = static_cast<size_t>(k) % n, next = (here + 1) % n;
  const RibbonPass a = railPass(rs, regions, thread.steps[here], shape, ribbon.swapped[here] != 0);
  const RibbonPass b = railPass(rs, regions, thread.steps[next], shape, ribbon.swapped[next] != 0);
  railP.clear();
  railQ.clear();
  const SegmentTurn turn = segmentTurn(a, b);
  for (int i = 0; i <= shape.samples; ++i) {
    const double t = static_cast<double>(i) / shape.samples;
    railP.push_back(segmentPoint(a, b, turn, 0, t));
    railQ.push_back(segmentPoint(a, b, turn, 1, t));
  }
}

std::vector<Ribbon> weaveRibbons(const RotationSystem& rs, const WeaveThreads& weave,
                                 const std::vector<EdgeRegion>& regions, const RibbonShape& shape,
                                 const std::vector<double>& edgeWidths) {
  requireShape(shape);
  if (!edgeWidths.empty() && edgeWidths.size() != regions.size()) {
    throw std::logic_error("internal: a width per edge expected");
  }
  std::vector<Ribbon> ribbons;
  ribbons.reserve(weave.threads.size());
  for (const Thread& thread : weave.threads) {
    Ribbon ribbon;
    ribbon.samples = shape.samples;
    ribbon.passes.reserve(thread.steps.size());
    // Rails: a connector joins the tail corner nearer the vertex the thread
    // passes to the next head corner nearer it (A7). A pass's side 0 is the
    // vertex side at its head; at its tail it is the vertex side beside an
    // untwisted edge but the centre side across a twisted one, whose strand
    // runs diagonally through the region. So rail P changes side after each
    // crossing.
    bool swapped = false;
    for (const ThreadStep& step : thread.steps) {
      ribbon.passes.push_back(railPass(rs, regions, step, shape, swapped, edgeWidths));
      ribbon.swapped.push_back(swapped ? 1 : 0);
      if (step.crossing != Crossing::None) swapped = !swapped;
    }
    // An orientable surface brings the rails back to their own sides: an
    // even number of crossings per thread (III.1.2: t flips at each).
    if (swapped) throw std::logic_error("internal: a thread crosses an odd number of twisted edges");
    const int n = shape.samples;
    const int passes = static_cast<int>(ribbon.passes.size());
    ribbon.railP.reserve(static_cast<size_t>(passes * n));
    ribbon.railQ.reserve(static_cast<size_t>(passes * n));
    for (int k = 0; k < passes; ++k) {
      const RibbonPass& here = ribbon.passes[static_cast<size_t>(k)];
      const RibbonPass& next = ribbon.passes[static_cast<size_t>((k + 1) % passes)];
      const SegmentTurn turn = segmentTurn(here, next);
      for (int i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / n;
        ribbon.railP.push_back(segmentPoint(here, next, turn, 0, t));
        ribbon.railQ.push_back(segmentPoint(here, next, turn, 1, t));
      }
    }
    ribbons.push_back(std::move(ribbon));
  }
  return ribbons;
}

}  // namespace rotafab::geometry
