#include "geometry/WovenPanels.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rotafab::geometry {
namespace {

int wrapped(int index, int size) { return ((index % size) + size) % size; }

// The pass index of the nearest down crossing from `pass`, going `step` (+1 or -1) along the thread.
int nearestDown(const Ribbon& ribbon, int pass, int step) {
  const int n = static_cast<int>(ribbon.passes.size());
  for (int k = 1; k < n; ++k) {
    const int at = pass + step * k;
    if (ribbon.passes[static_cast<size_t>(wrapped(at, n))].crossing == Crossing::Down) return at;
  }
  return pass;
}

void unfold(WovenPanel& panel, const Point3& normal) {
  const int rows = panel.rows();
  std::vector<Point3> points(panel.railP);
  points.insert(points.end(), panel.railQ.begin(), panel.railQ.end());
  std::vector<Point2> flat(points.size(), Point2::Zero());
  std::vector<char> placed(points.size(), 0);
  const int u = panel.upRow;
  const Point3 across = panel.railQ[static_cast<size_t>(u)] - panel.railP[static_cast<size_t>(u)];
  flat[static_cast<size_t>(u)] = Point2(0, 0);
  flat[static_cast<size_t>(rows + u)] = Point2(across.norm(), 0);
  placed[static_cast<size_t>(u)] = placed[static_cast<size_t>(rows + u)] = 1;
  // The frame of eq. 4.18-4.21 at the up row: x along P Q, y = N_e x x, so
  // that N_e maps to +z. A triangle's first new corner goes to the side of
  // y it lies on in space.
  const Point3 x = across.normalized(), y = normal.cross(x).normalized();
  const auto awayFrom = [&](int row) {
    const double side = (points[static_cast<size_t>(row)] - panel.railP[static_cast<size_t>(u)]).dot(y);
    return Point2(across.norm() / 2, side > 0 ? -1.0 : 1.0);
  };
  std::vector<std::array<int, 3>> ahead, behind;
  for (int i = u; i + 1 < rows; ++i) {
    ahead.push_back({i, rows + i, i + 1});
    ahead.push_back({rows + i, rows + i + 1, i + 1});
  }
  for (int i = u; i > 0; --i) {
    behind.push_back({rows + i - 1, rows + i, i});
    behind.push_back({i - 1, rows + i - 1, i});
  }
  if (!ahead.empty()) unfoldStrip(points, ahead, flat, placed, awayFrom(u + 1));
  if (!behind.empty()) unfoldStrip(points, behind, flat, placed, awayFrom(rows + u - 1));
  panel.flatP.assign(flat.begin(), flat.begin() + rows);
  panel.flatQ.assign(flat.begin() + rows, flat.end());
}

}  // namespace

std::vector<Point2> WovenPanel::outlineOfRows(int first, int last) const {
  std::vector<Point2> outline(flatP.begin() + first, flatP.begin() + last + 1);
  for (int i = last; i >= first; --i) outline.push_back(flatQ[static_cast<size_t>(i)]);
  if (core::signedArea(outline) < 0) std::reverse(outline.begin(), outline.end());
  return outline;
}

double WovenPanel::areaOfRows(int first, int last) const {
  double area = 0;
  for (int i = first; i < last; ++i) {
    const Point3 &p0 = railP[static_cast<size_t>(i)], &p1 = railP[static_cast<size_t>(i + 1)];
    const Point3 &q0 = railQ[static_cast<size_t>(i)], &q1 = railQ[static_cast<size_t>(i + 1)];
    area += (q0 - p0).cross(p1 - p0).norm() / 2 + (q1 - q0).cross(p1 - q0).norm() / 2;
  }
  return area;
}

std::vector<Point2> WovenPanel::outline() const { return outlineOfRows(0, rows() - 1); }

const Point3& WovenPanel::corner(int index) const {
  return index < rows() ? railP[static_cast<size_t>(index)] : railQ[static_cast<size_t>(index - rows())];
}

const Point2& WovenPanel::flatCorner(int index) const {
  return index < rows() ? flatP[static_cast<size_t>(index)] : flatQ[static_cast<size_t>(index - rows())];
}

Point3 StripPoint::inSpace(const WovenPanel& panel) const {
  Point3 p = Point3::Zero();
  for (int i = 0; i < 3; ++i) p += weights[static_cast<size_t>(i)] * panel.corner(corners[static_cast<size_t>(i)]);
  return p;
}

Point2 StripPoint::onPanel(const WovenPanel& panel) const {
  Point2 p = Point2::Zero();
  for (int i = 0; i < 3; ++i) p += weights[static_cast<size_t>(i)] * panel.flatCorner(corners[static_cast<size_t>(i)]);
  return p;
}

StripPoint stripPointOnLine(const WovenPanel& panel, int first, int last, const Point3& point,
                            const Point3& direction) {
  first = std::max(first, 0);
  last = std::min(last, panel.rows() - 1);
  const int rows = panel.rows();
  StripPoint best;
  double bestInside = -std::numeric_limits<double>::infinity(), bestAlong = std::numeric_limits<double>::infinity();
  for (int i = first; i < last; ++i) {
    for (const std::array<int, 3>& t :
         {std::array<int, 3>{i, rows + i, i + 1}, std::array<int, 3>{rows + i, rows + i + 1, i + 1}}) {
      const Point3 &a = panel.corner(t[0]), &b = panel.corner(t[1]), &c = panel.corner(t[2]);
      // The line's parameter and the barycentric weights at once (Möller and
      // Trumbore, "Fast, minimum storage ray-triangle intersection", 1997).
      const Point3 e1 = b - a, e2 = c - a, p = direction.cross(e2);
      const double det = e1.dot(p);
      if (!(std::abs(det) > 1e-18)) continue;
      const Point3 s = point - a, q = s.cross(e1);
      const Eigen::Vector3d solved(s.dot(p) / det, direction.dot(q) / det, e2.dot(q) / det);
      const std::array<double, 3> w{1 - solved.x() - solved.y(), solved.x(), solved.y()};
      const double inside = std::min({w[0], w[1], w[2]});
      const double along = std::abs(solved.z());
      // Inside beats outside; among triangles the line meets, the nearest along it.
      const bool better = inside >= -1e-12 ? (bestInside < -1e-12 || along < bestAlong) : inside > bestInside;
      if (better) {
        best.corners = t;
        best.weights = w;
        bestInside = inside;
        bestAlong = inside >= -1e-12 ? along : bestAlong;
      }
    }
  }
  if (!std::isfinite(bestInside)) {
    // No triangle there to meet (all of zero area): no point of the strip.
    best.weights = {1, 0, 0};
    best.miss = std::numeric_limits<double>::infinity();
    return best;
  }
  if (bestInside < -1e-12) {
    double sum = 0;
    for (double& w : best.weights) sum += (w = std::max(w, 0.0));
    for (double& w : best.weights) w /= sum;
    const Point3 q = best.inSpace(panel);
    best.miss = (q - point).cross(direction.normalized()).norm();
  }
  return best;
}

std::vector<WovenPanel> wovenPanels(const std::vector<Ribbon>& ribbons, const std::vector<EdgeRegion>& regions,
                                    int overlapRows) {
  std::vector<WovenPanel> panels;
  for (size_t r = 0; r < ribbons.size(); ++r) {
    const Ribbon& ribbon = ribbons[r];
    const int passes = static_cast<int>(ribbon.passes.size());
    const int total = static_cast<int>(ribbon.railP.size()), n = ribbon.samples;
    const int overlap = std::clamp(overlapRows, 0, n / 2);
    for (int k = 0; k < passes; ++k) {
      const RibbonPass& pass = ribbon.passes[static_cast<size_t>(k)];
      if (pass.crossing != Crossing::Up) continue;
      const int before = nearestDown(ribbon, k, -1), after = nearestDown(ribbon, k, +1);
      WovenPanel panel;
      panel.thread = static_cast<int>(r);
      panel.upPass = k;
      panel.upEdge = pass.edge;
      panel.downEdges = {ribbon.passes[static_cast<size_t>(wrapped(before, passes))].edge,
                         ribbon.passes[static_cast<size_t>(wrapped(after, passes))].edge};
      const int firstRow = before * n - overlap, lastRow = after * n + overlap;
      if (before == k || lastRow - firstRow >= total) {
        throw std::invalid_argument(
            fmt::format("thread {} crosses under only once, so its one panel would go all round it", r + 1));
      }
      panel.firstRow = wrapped(firstRow, total);
      panel.upRow = k * n - firstRow;
      panel.downRows = {before * n - firstRow, after * n - firstRow};
      for (int row = firstRow; row <= lastRow; ++row) {
        panel.railP.push_back(ribbon.railP[static_cast<size_t>(wrapped(row, total))]);
        panel.railQ.push_back(ribbon.railQ[static_cast<size_t>(wrapped(row, total))]);
      }
      unfold(panel, regions[static_cast<size_t>(pass.edge)].normal);
      panel.area = panel.areaOfRows(0, panel.rows() - 1);
      panels.push_back(std::move(panel));
    }
  }
  return panels;
}

}  // namespace rotafab::geometry
