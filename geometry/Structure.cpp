#include "geometry/Structure.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <unordered_map>

#include <Eigen/Geometry>

#include "core/Decimal.h"
#include "geometry/FastenerHoles.h"

namespace rotafab::geometry {

std::string_view structureName(StructureKind kind) { return kind == StructureKind::Band ? "band" : "weave"; }

std::string_view roleName(LabelRole role) {
  switch (role) {
    case LabelRole::Edge:
      return "edge";
    case LabelRole::Panel:
      return "panel";
    case LabelRole::Neighbor:
      return "neighbor";
    case LabelRole::Up:
      return "up";
    case LabelRole::Down:
      return "down";
    case LabelRole::Piece:
      return "piece";
  }
  return "edge";
}

std::string_view fasteningName(PieceFastening fastening) {
  switch (fastening) {
    case PieceFastening::Band:
      return "band";
    case PieceFastening::Glue:
      return "glue";
    case PieceFastening::Tab:
      break;
  }
  return "tab";
}

std::vector<AssemblyStep> stepsInPanelOrder(const std::vector<Panel>& panels) {
  // A band's half cut off (of either panel's copy) goes on when its edge is joined.
  std::map<int, std::vector<std::string>> halvesOfEdge;
  for (const Panel& panel : panels) {
    for (const PanelPiece& piece : panel.pieces) {
      if (piece.fastening == PieceFastening::Band) halvesOfEdge[piece.edge].push_back(piece.name);
    }
  }
  std::vector<AssemblyStep> steps;
  for (const Panel& panel : panels) {
    // A band's holes are on the panel, or on the piece it was cut off as.
    std::map<int, int> holesOfEdge;
    for (const PanelHole& hole : panel.holes) ++holesOfEdge[hole.edge];
    AssemblyStep step{panel.id, {}, {}, {}};
    for (const PanelPiece& piece : panel.pieces) {
      for (const PanelHole& hole : piece.holes) ++holesOfEdge[hole.edge];
      if (piece.fastening == PieceFastening::Tab) step.pieces.push_back(piece.name);
      if (piece.fastening == PieceFastening::Glue) step.gluedPieces.push_back(piece.name);
    }
    for (const PanelJoin& join : panel.joins) {
      if (join.panel >= panel.id) continue;
      step.joins.push_back({join.panel, join.edge, holesOfEdge[join.edge], halvesOfEdge[join.edge]});
    }
    steps.push_back(std::move(step));
  }
  return steps;
}

namespace {

// The corners of a panel's polygons, each point once (the same point
// exactly), so that each panel is one connected surface; panels share none,
// being separate pieces of material. Kept from panel to panel for its
// buckets.
class PanelCorners {
 public:
  PolygonMesh surface(const Panel& panel) {
    corners_.clear();
    PolygonMesh surface;
    for (const auto& polygon : panel.surface) {
      std::vector<int> face;
      face.reserve(polygon.size());
      for (const Point3& p : polygon) {
        const auto [at, added] = corners_.try_emplace(p, surface.vertexCount());
        if (added) surface.positions.push_back(p);
        face.push_back(at->second);
      }
      surface.faces.push_back(std::move(face));
    }
    return surface;
  }

 private:
  struct Hash {
    size_t operator()(const Point3& p) const {
      size_t h = 0;
      for (int axis = 0; axis < 3; ++axis) h = h * 0x9E3779B97F4A7C15ull + std::hash<double>{}(p[axis]);
      return h;
    }
  };
  struct Equal {
    bool operator()(const Point3& a, const Point3& b) const { return a == b; }
  };
  std::unordered_map<Point3, int, Hash, Equal> corners_;
};

}  // namespace

PolygonMesh surfaceMesh(const Structure& structure) {
  PolygonMesh surface;
  PanelCorners corners;
  for (const Panel& panel : structure.panels) {
    PolygonMesh here = corners.surface(panel);
    const int offset = surface.vertexCount();
    surface.positions.insert(surface.positions.end(), here.positions.begin(), here.positions.end());
    for (auto& face : here.faces) {
      for (int& v : face) v += offset;
      surface.faces.push_back(std::move(face));
    }
  }
  return surface;
}

void writeStructureObj(std::ostream& out, const Structure& structure, std::string_view comment, int decimals) {
  fmt::memory_buffer buffer;
  fmt::format_to(std::back_inserter(buffer), "# {}\n", comment);
  size_t written = 0;  // vertices, before this panel's
  PanelCorners corners;
  for (const Panel& panel : structure.panels) {
    const PolygonMesh surface = corners.surface(panel);
    for (const Point3& p : surface.positions) {
      buffer.push_back('v');
      for (int axis = 0; axis < 3; ++axis) {
        buffer.push_back(' ');
        core::appendUnits(buffer, core::unitsOf(p[axis], decimals), decimals);
      }
      buffer.push_back('\n');
    }
    fmt::format_to(std::back_inserter(buffer), "g panel-{}\n", panel.id);
    for (const auto& face : surface.faces) {
      buffer.push_back('f');
      for (int v : face) {
        buffer.push_back(' ');
        core::appendUnits(buffer, static_cast<int64_t>(written) + v + 1, 0);
      }
      buffer.push_back('\n');
    }
    written += surface.positions.size();
    // A few megabytes at a time: a large structure's text is never held whole.
    if (buffer.size() >= (size_t{4} << 20)) {
      out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
      buffer.clear();
    }
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

GrownStructure growUntilRoom(PolygonMesh& mesh, const std::function<Structure(const PolygonMesh&)>& build,
                             const core::WorkContext& context) {
  GrownStructure result;
  std::vector<double> firstScales;  // of the size given
  int withoutRoomBefore = std::numeric_limits<int>::max();
  for (int attempt = 1;; ++attempt) {
    try {
      result.structure = build(mesh);
      return result;
    } catch (const NoRoomForHoleError& error) {
      if (attempt == 1) firstScales = error.scales;
      const bool fewer = error.bands < withoutRoomBefore;
      withoutRoomBefore = error.bands;
      if (attempt >= kMostGrowAttempts || (attempt >= kGrowAttempts && !fewer) || !std::isfinite(error.scaleNeeded)) {
        NoRoomForHoleError last = error;
        last.scales = firstScales;
        throw last;
      }
      if (attempt == 1) result.bandsWithoutRoom = error.bands, result.scalesNeeded = error.scales;
      result.grown *= error.scaleNeeded;
      for (Point3& p : mesh.positions) p *= error.scaleNeeded;
      context.report({"geometry", "larger, for the fasteners", static_cast<size_t>(attempt), 0});
    }
  }
}

namespace {

// Andrew's monotone chain: the convex hull, counter-clockwise.
std::vector<Point2> convexHull(std::vector<Point2> points) {
  std::sort(points.begin(), points.end(),
            [](const Point2& a, const Point2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  if (points.size() < 3) return points;
  std::vector<Point2> hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && core::turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && core::turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// The turn (radians, counter-clockwise) that lays the least-area box of
// `outline` along the axes, its longer side along x.
double leastBoxTurn(const Polyline2& outline) {
  const std::vector<Point2> hull = convexHull(outline);
  if (hull.size() < 3) return 0;
  double bestArea = std::numeric_limits<double>::infinity(), bestTurn = 0;
  for (size_t i = 0; i < hull.size(); ++i) {
    const Point2 side = hull[(i + 1) % hull.size()] - hull[i];
    if (side.norm() == 0) continue;
    const Point2 u = side.normalized(), v(-u.y(), u.x());
    double lowU = std::numeric_limits<double>::infinity(), highU = -lowU, lowV = lowU, highV = -lowU;
    for (const Point2& p : hull) {
      lowU = std::min(lowU, p.dot(u)), highU = std::max(highU, p.dot(u));
      lowV = std::min(lowV, p.dot(v)), highV = std::max(highV, p.dot(v));
    }
    const double area = (highU - lowU) * (highV - lowV);
    // (A hair's preference for what was first: the same turn from run to run on a square.)
    if (area < bestArea * (1 - 1e-9)) {
      bestArea = area;
      // Turning by -angle(u) lays u along x; a quarter turn more when v's extent is the longer.
      bestTurn = -std::atan2(u.y(), u.x()) + (highV - lowV > highU - lowU ? std::numbers::pi / 2 : 0);
    }
  }
  return bestTurn;
}

void turnLabels(std::vector<PanelLabel>& labels, const Eigen::Rotation2Dd& rotation) {
  for (PanelLabel& label : labels) {
    label.box.origin = rotation * label.box.origin;
    label.box.angle += rotation.angle();
    label.box.along = Point2(std::cos(label.box.angle), std::sin(label.box.angle));
    for (Polyline2& stroke : label.strokes) {
      for (Point2& p : stroke) p = rotation * p;
    }
  }
}

void turnPanel(Panel& panel, double angle) {
  const Eigen::Rotation2Dd rotation(angle);
  const auto turnAll = [&](Polyline2& points) {
    for (Point2& p : points) p = rotation * p;
  };
  turnAll(panel.outline);
  for (PanelHole& hole : panel.holes) hole.xy = rotation * hole.xy;
  turnLabels(panel.labels, rotation);
  for (PanelPiece& piece : panel.pieces) {
    turnAll(piece.outline);
    for (PanelHole& hole : piece.holes) hole.xy = rotation * hole.xy;
    turnLabels(piece.labels, rotation);
  }
  for (Polyline2& score : panel.scores) turnAll(score);
}

}  // namespace

void layPanelsAlongTheirLeastBoxes(std::vector<Panel>& panels, const core::WorkContext& context) {
  context.parallelFor(panels.size(), [&](size_t i) {
    const double angle = leastBoxTurn(panels[i].outline);
    if (angle != 0) turnPanel(panels[i], angle);
  });
}

}  // namespace rotafab::geometry
