#include "jobs/Manifest.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

namespace rotafab::jobs {

std::vector<Part> bandParts(const geometry::BandStructure& structure) {
  std::vector<Part> parts;
  for (const geometry::Panel& panel : structure.panels) {
    Part part;
    part.name = fmt::format("panel {}", panel.id);
    part.order = panel.id - 1;
    part.outline = panel.outline;
    for (const geometry::PanelHole& hole : panel.holes) {
      Polygon2 circle;
      for (int i = 0; i < kHoleSides; ++i) {
        const double a = 2 * std::numbers::pi * i / kHoleSides;
        circle.push_back(hole.xy + hole.diameter / 2 * Point2(std::cos(a), std::sin(a)));
      }
      part.holes.push_back(std::move(circle));
    }
    for (const geometry::PanelLabel& label : panel.labels) {
      part.etch.insert(part.etch.end(), label.strokes.begin(), label.strokes.end());
    }
    part.score = panel.scores;
    parts.push_back(std::move(part));
  }
  return parts;
}

namespace {

nlohmann::ordered_json point(const Point2& p) { return {p.x(), p.y()}; }

}  // namespace

nlohmann::ordered_json bandManifest(const geometry::BandStructure& structure, const MeshCounts& mesh,
                                    const profiles::Bed& bed, const SheetPlan& plan,
                                    const std::vector<std::vector<std::string>>& files) {
  nlohmann::ordered_json manifest;
  manifest["version"] = 1;
  manifest["structure"] = "band";
  manifest["units"] = "in";
  manifest["mesh"] = {{"vertices", mesh.vertices},
                      {"edges", mesh.edges},
                      {"faces", mesh.faces},
                      {"genus", mesh.genus ? nlohmann::ordered_json(*mesh.genus) : nlohmann::ordered_json(nullptr)}};
  manifest["bed"] = {{"width", bed.width}, {"height", bed.height}, {"margin", bed.margin}};
  manifest["fasteners"] = structure.fasteners;
  manifest["sheets"] = nlohmann::ordered_json::array();
  for (size_t s = 0; s < plan.sheets.size(); ++s) {
    nlohmann::ordered_json panels = nlohmann::ordered_json::array();
    for (const PlannedPart& placed : plan.parts) {
      if (placed.sheet == static_cast<int>(s) + 1) panels.push_back(structure.panels[placed.part].id);
    }
    manifest["sheets"].push_back({{"index", s + 1}, {"files", files.at(s)}, {"panels", panels}});
  }
  std::vector<const PlannedPart*> placement(structure.panels.size());
  for (const PlannedPart& placed : plan.parts) placement[placed.part] = &placed;
  manifest["panels"] = nlohmann::ordered_json::array();
  for (size_t i = 0; i < structure.panels.size(); ++i) {
    const geometry::Panel& panel = structure.panels[i];
    const PlannedPart& placed = *placement[i];
    nlohmann::ordered_json entry;
    entry["id"] = panel.id;
    entry["order"] = placed.cuttingIndex + 1;  // its place in the cutting order
    entry["sheet"] = placed.sheet;
    entry["source"] = {{"face", panel.face}};
    entry["outline"] = nlohmann::ordered_json::array();
    for (const Point2& p : panel.outline) entry["outline"].push_back(point(p));
    entry["placement"] = {{"x", placed.x}, {"y", placed.y}, {"rotation", placed.rotation}};
    entry["holes"] = nlohmann::ordered_json::array();
    for (const auto& hole : panel.holes) {
      entry["holes"].push_back({{"edge", hole.edge}, {"xy", point(hole.xy)}, {"diameter", hole.diameter}});
    }
    entry["labels"] = nlohmann::ordered_json::array();
    for (const auto& label : panel.labels) {
      nlohmann::ordered_json l = {
          {"text", label.role == "edge" ? std::to_string(label.edge) : std::to_string(panel.id)}};
      if (label.role == "edge") l["edge"] = label.edge;
      l["role"] = label.role;
      entry["labels"].push_back(l);
    }
    entry["neighbors"] = panel.neighbors;
    entry["area"] = panel.area;
    // Extensions: the edge number joining each neighbour (same order), and
    // how far the layout moved the panel from its assembly order.
    entry["edges"] = panel.edges;
    entry["moved"] = placed.moved;
    manifest["panels"].push_back(entry);
  }
  return manifest;
}

std::string manifestText(const nlohmann::json& manifest) {
  try {
    const auto& panels = manifest.at("panels");
    std::map<int, const nlohmann::json*> byId;
    for (const auto& panel : panels) byId[panel.at("id").get<int>()] = &panel;
    std::string text = fmt::format(
        "Assembly manifest: {} structure, {} panels on {} sheet{}, {} fasteners\n"
        "Join the panels in this order (flood fill from panel 1, the base). Each edge band overlaps the band\n"
        "with the same number on the panel named; fasten them through their holes.\n\n",
        manifest.at("structure").get<std::string>(), panels.size(), manifest.at("sheets").size(),
        manifest.at("sheets").size() == 1 ? "" : "s", manifest.at("fasteners").get<int>());
    int total = 0;
    for (const auto& [id, panel] : byId) {
      const auto& neighbors = panel->at("neighbors");
      const auto& edges = panel->at("edges");
      std::map<int, int> holesOfEdge;
      for (const auto& hole : panel->at("holes")) ++holesOfEdge[hole.at("edge").get<int>()];
      std::string joins;
      int fasteners = 0;
      for (size_t j = 0; j < neighbors.size(); ++j) {
        const int other = neighbors[j].get<int>(), edge = edges.at(j).get<int>();
        if (other >= id) continue;
        joins += fmt::format("{}panel {} at edge {} ({} fastener{})", joins.empty() ? "" : ", ", other, edge,
                             holesOfEdge[edge], holesOfEdge[edge] == 1 ? "" : "s");
        fasteners += holesOfEdge[edge];
      }
      total += fasteners;
      text += fmt::format("step {:>4}: panel {} (sheet {}): {}\n", id, id, panel->at("sheet").get<int>(),
                          joins.empty() ? "start here, the base" : "join to " + joins);
    }
    text += fmt::format("\n{} fasteners in all\n", total);
    return text;
  } catch (const nlohmann::json::exception& error) {
    throw std::invalid_argument(fmt::format("the manifest is not SPEC's version 1: {}", error.what()));
  }
}

}  // namespace rotafab::jobs
