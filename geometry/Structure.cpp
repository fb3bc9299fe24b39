#include "geometry/Structure.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>

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

}  // namespace rotafab::geometry
