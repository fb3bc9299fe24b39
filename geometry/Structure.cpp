#include "geometry/Structure.h"

#include <fmt/format.h>

#include <map>

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
  for (const Panel& panel : structure.panels) {
    for (const auto& polygon : panel.surface) {
      std::vector<int> face;
      for (const Point3& p : polygon) {
        face.push_back(surface.vertexCount());
        surface.positions.push_back(p);
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
