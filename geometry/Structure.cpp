#include "geometry/Structure.h"

#include <fmt/format.h>

#include <map>
#include <unordered_map>

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

PolygonMesh surfaceMesh(const Structure& structure) {
  PolygonMesh surface;
  // A panel's polygons share the corners they have in common (the same
  // point exactly), so that each panel is one connected surface; panels
  // share none, being separate pieces of material.
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
  std::unordered_map<Point3, int, Hash, Equal> corners;
  for (const Panel& panel : structure.panels) {
    corners.clear();
    for (const auto& polygon : panel.surface) {
      std::vector<int> face;
      face.reserve(polygon.size());
      for (const Point3& p : polygon) {
        const auto [at, added] = corners.try_emplace(p, surface.vertexCount());
        if (added) surface.positions.push_back(p);
        face.push_back(at->second);
      }
      surface.faces.push_back(std::move(face));
    }
  }
  return surface;
}

std::vector<ObjGroup> panelGroups(const Structure& structure) {
  std::vector<ObjGroup> groups;
  int face = 0;
  for (const Panel& panel : structure.panels) {
    groups.push_back({face, fmt::format("panel-{}", panel.id)});
    face += static_cast<int>(panel.surface.size());
  }
  return groups;
}

}  // namespace rotafab::geometry
