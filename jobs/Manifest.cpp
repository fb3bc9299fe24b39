#include "jobs/Manifest.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "core/UserError.h"
#include "geometry/WeaveStructure.h"
#include "jobs/JobCost.h"
#include "jobs/ManifestSteps.h"
#include "jobs/SvgWriter.h"
#include "toolpath/JsonErrors.h"

namespace rotafab::jobs {

namespace {

// To the sheets' 0.0001 in (kSheetDecimals): the outlines are what the sheets
// cut, and nine more digits of each would only make the file larger.
double onGrid(double v) {
  constexpr double kScale = 10000.0;
  static_assert(kSheetDecimals == 4);
  return std::round(v * kScale) / kScale + 0.0;  // + 0.0: no "-0.0"
}
nlohmann::ordered_json point(const Point2& p) { return {onGrid(p.x()), onGrid(p.y())}; }

// The manifest's `source` (docs/CONTRACT.md, "manifest.json (version 1)"): a
// band panel's face (a cap of --holes fill has none in the file), a woven
// panel's edge and cycle.
nlohmann::ordered_json sourceOf(const geometry::PanelSource& source) {
  if (source.edge >= 0) return {{"edge", source.edge}, {"cycle", source.cycle}};
  if (source.cap) return {{"face", nullptr}, {"cap", true}};
  return {{"face", source.face}};
}

}  // namespace

nlohmann::ordered_json repairsJson(const std::vector<geometry::MeshRepair>& repairs) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const geometry::MeshRepair& repair : repairs) {
    nlohmann::ordered_json item = {{"kind", repair.kind}, {"count", repair.count}, {"first", repair.first}};
    if (repair.moved > 0) item["moved"] = std::round(repair.moved * 10000) / 10000;
    list.push_back(std::move(item));
  }
  return list;
}

nlohmann::ordered_json simplifiedJson(const PanelCount& count) {
  const geometry::Remeshing& remeshing = count.remeshing;
  nlohmann::ordered_json json = {
      {"asked", count.asked}, {"faces", remeshing.facesAfter}, {"remeshed", remeshing.remeshed}};
  if (remeshing.remeshed) json["smallest_face"] = std::round(remeshing.smallestAreaRatio * 1000) / 1000;
  return json;
}

nlohmann::ordered_json stabilityJson(const geometry::Stability& stability) {
  const auto point = [](const geometry::Point3& p) { return nlohmann::ordered_json::array({p.x(), p.y(), p.z()}); };
  nlohmann::ordered_json hang = nlohmann::ordered_json::array(), footprint = nlohmann::ordered_json::array();
  for (const geometry::Point3& p : stability.hangPoints) hang.push_back(point(p));
  for (const geometry::Point3& p : stability.footprint) footprint.push_back(point(p));
  return {{"stands", stability.stands},
          {"margin", stability.margin},
          {"center_of_mass", point(stability.centerOfMass)},
          {"mass_kg", stability.massKg ? nlohmann::ordered_json(*stability.massKg) : nlohmann::ordered_json(nullptr)},
          {"hang_points", hang},
          {"footprint", footprint}};
}

namespace {

// Where each panel and each piece was placed, from the planned parts in
// structureParts()'s order.
struct Placements {
  std::vector<const PlannedPart*> panels;
  std::map<std::pair<int, int>, const PlannedPart*> pieces;
};

Placements placementsOf(const geometry::Structure& structure, const SheetPlan& plan) {
  const std::vector<std::pair<int, int>> owners = partOwners(structure);
  Placements placements;
  placements.panels.resize(structure.panels.size());
  for (const PlannedPart& placed : plan.parts) {
    const auto [panel, piece] = owners.at(placed.part);
    if (piece < 0) {
      placements.panels[panel] = &placed;
    } else {
      placements.pieces[{panel, piece}] = &placed;
    }
  }
  return placements;
}

// Everything but "panels".
nlohmann::ordered_json manifestHead(const geometry::Structure& structure, const BuiltMesh& mesh,
                                    const profiles::Bed& bed, const SheetPlan& plan,
                                    const std::vector<std::vector<std::string>>& files) {
  nlohmann::ordered_json manifest;
  manifest["version"] = 1;
  manifest["structure"] = geometry::structureName(structure.kind);
  manifest["units"] = "in";
  manifest["mesh"] = {{"vertices", mesh.vertices},
                      {"edges", mesh.edges},
                      {"faces", mesh.faces},
                      {"genus", mesh.genus ? nlohmann::ordered_json(*mesh.genus) : nlohmann::ordered_json(nullptr)}};
  if (!mesh.repairs.empty()) manifest["repairs"] = repairsJson(mesh.repairs);
  if (mesh.panelCount) manifest["simplified"] = simplifiedJson(*mesh.panelCount);
  manifest["bed"] = {{"width", bed.width}, {"height", bed.height}, {"margin", bed.margin}};
  manifest["fasteners"] = structure.fasteners;
  const std::vector<std::pair<int, int>> owners = partOwners(structure);
  manifest["sheets"] = nlohmann::ordered_json::array();
  for (size_t s = 0; s < plan.sheets.size(); ++s) {
    nlohmann::ordered_json panels = nlohmann::ordered_json::array(), pieces = nlohmann::ordered_json::array();
    for (const PlannedPart& placed : plan.parts) {
      if (placed.sheet != static_cast<int>(s) + 1) continue;
      const auto [panel, piece] = owners.at(placed.part);
      if (piece < 0) {
        panels.push_back(structure.panels[panel].id);
      } else {
        pieces.push_back(structure.panels[panel].pieces[piece].name);
      }
    }
    nlohmann::ordered_json sheet = {{"index", s + 1}, {"files", files.at(s)}, {"panels", panels}};
    sheet["preview"] = previewFile(static_cast<int>(s) + 1);  // extension: the sheet for people to look at
    if (!pieces.empty()) sheet["pieces"] = pieces;            // extension: the pieces of split panels it holds
    manifest["sheets"].push_back(sheet);
  }
  return manifest;
}

// Panel i's entry. Without its shapes (outlines, placements, holes' places)
// it is what the assembly steps read (stepsOf), in a fraction of the memory.
nlohmann::ordered_json panelEntry(const geometry::Structure& structure, size_t i, const Placements& placements,
                                  bool shapes) {
  const geometry::Panel& panel = structure.panels[i];
  const PlannedPart& placed = *placements.panels[i];
  nlohmann::ordered_json entry;
  entry["id"] = panel.id;
  entry["order"] = placed.cuttingIndex + 1;  // its place in the cutting order
  entry["sheet"] = placed.sheet;
  entry["source"] = sourceOf(panel.source);
  if (shapes) {
    entry["outline"] = nlohmann::ordered_json::array();
    for (const Point2& p : panel.outline) entry["outline"].push_back(point(p));
    entry["placement"] = {{"x", placed.x}, {"y", placed.y}, {"rotation", placed.rotation}};
  }
  const auto holeEntry = [&](const geometry::PanelHole& hole) {
    return shapes ? nlohmann::ordered_json{{"edge", hole.edge}, {"xy", point(hole.xy)}, {"diameter", hole.diameter}}
                  : nlohmann::ordered_json{{"edge", hole.edge}};
  };
  entry["holes"] = nlohmann::ordered_json::array();
  for (const auto& hole : panel.holes) entry["holes"].push_back(holeEntry(hole));
  // What each label shows (without the mark of 6 and 9): an edge's number,
  // the panel's own, or a piece's name ("17a").
  const auto labelsJson = [&](const std::vector<geometry::PanelLabel>& labels) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const auto& label : labels) {
      nlohmann::ordered_json l = {{"text", label.role == geometry::LabelRole::Piece ? label.text
                                           : label.edge > 0                         ? std::to_string(label.edge)
                                                                                    : std::to_string(panel.id)}};
      if (label.edge > 0) l["edge"] = label.edge;
      l["role"] = geometry::roleName(label.role);
      list.push_back(l);
    }
    return list;
  };
  entry["labels"] = labelsJson(panel.labels);
  std::vector<int> neighbors, edges;
  for (const geometry::PanelJoin& join : panel.joins) neighbors.push_back(join.panel), edges.push_back(join.edge);
  entry["neighbors"] = neighbors;
  entry["area"] = panel.area;
  // Extensions: the edge number joining each neighbour (same order), and
  // how far the layout moved the panel from its assembly order.
  entry["edges"] = edges;
  entry["moved"] = placed.moved;
  // Extension: the bands cut off a panel that would overlap itself (V.4),
  // each a part of its own with a tab fastened to the vertex band, or the
  // far half of a band cut across, held by the band's other copy.
  if (!panel.pieces.empty()) {
    entry["pieces"] = nlohmann::ordered_json::array();
    for (size_t k = 0; k < panel.pieces.size(); ++k) {
      const geometry::PanelPiece& piece = panel.pieces[k];
      const PlannedPart& at = *placements.pieces.at({static_cast<int>(i), static_cast<int>(k)});
      nlohmann::ordered_json p;
      p["name"] = piece.name;
      p["edge"] = piece.edge;
      p["sheet"] = at.sheet;
      p["order"] = at.cuttingIndex + 1;
      if (shapes) {
        p["outline"] = nlohmann::ordered_json::array();
        for (const Point2& q : piece.outline) p["outline"].push_back(point(q));
        p["placement"] = {{"x", at.x}, {"y", at.y}, {"rotation", at.rotation}};
      }
      p["holes"] = nlohmann::ordered_json::array();
      for (const auto& hole : piece.holes) p["holes"].push_back(holeEntry(hole));
      p["area"] = piece.area;
      p["fastened"] = geometry::fasteningName(piece.fastening);           // extension: by a tab, or by its band
      if (!piece.labels.empty()) p["labels"] = labelsJson(piece.labels);  // extension: what is etched on it
      entry["pieces"].push_back(p);
    }
  }
  return entry;
}

}  // namespace

namespace {

// manifestJsonText() with `linesOf(key, array, text)` giving the elements
// of the arrays "sheets" and "panels" a line each (after the first's "[").
template <class Lines>
std::string jsonTextWithLines(const nlohmann::ordered_json& manifest, const Lines& linesOf) {
  if (!manifest.is_object()) return manifest.dump() + "\n";
  std::string text = "{";
  bool first = true;
  for (const auto& [key, value] : manifest.items()) {
    text += first ? "\n " : ",\n ";
    first = false;
    text += nlohmann::ordered_json(key).dump();
    text += ": ";
    if (value.is_array() && !value.empty() && (key == "sheets" || key == "panels")) {
      text += "[";
      linesOf(key, value, text);
      text += "\n ]";
    } else {
      text += value.dump();
    }
  }
  text += "\n}\n";
  return text;
}

// Elements `from` to `to` of an array, a line each, as `line(i)` gives them.
template <class Line>
void appendLines(size_t from, size_t to, std::string& text, const Line& line) {
  for (size_t i = from; i < to; ++i) {
    text += i == 0 ? "\n  " : ",\n  ";
    text += line(i);
  }
}

}  // namespace

std::string manifestJsonText(const nlohmann::ordered_json& manifest) {
  return jsonTextWithLines(manifest, [](const std::string&, const nlohmann::ordered_json& array, std::string& text) {
    appendLines(0, array.size(), text, [&](size_t i) { return array[i].dump(); });
  });
}

ManifestFiles manifestFiles(const geometry::Structure& structure, const BuiltMesh& mesh, const profiles::Bed& bed,
                            const SheetPlan& plan, const std::vector<std::vector<std::string>>& files,
                            const nlohmann::ordered_json& more, const core::WorkContext& context) {
  // The manifest without the panels' shapes: what manifest.txt reads, and
  // the frame of manifest.json, whose panels' lines are made from the
  // structure a chunk at a time.
  nlohmann::ordered_json manifest = manifestHead(structure, mesh, bed, plan, files);
  const Placements placements = placementsOf(structure, plan);
  manifest["panels"] = nlohmann::ordered_json::array();
  for (size_t i = 0; i < structure.panels.size(); ++i) {
    manifest["panels"].push_back(panelEntry(structure, i, placements, false));
  }
  // Each sheet's kit (the steps it holds, and what can be done once it is cut).
  const std::vector<SheetKit> kits = sheetKits(manifest);
  for (size_t s = 0; s < kits.size(); ++s) {
    auto& sheet = manifest["sheets"][s];
    if (kits[s].run && kits[s].first > 0) sheet["kit"] = {kits[s].first, kits[s].last};
    sheet["completes"] = kits[s].completes;
  }
  for (const auto& [key, value] : more.items()) manifest[key] = value;
  ManifestFiles out;
  out.json =
      jsonTextWithLines(manifest, [&](const std::string& key, const nlohmann::ordered_json& array, std::string& text) {
        if (key != "panels") {
          appendLines(0, array.size(), text, [&](size_t i) { return array[i].dump(); });
          return;
        }
        constexpr size_t kChunk = 1024;
        std::vector<std::string> chunks((array.size() + kChunk - 1) / kChunk);
        context.parallelFor(chunks.size(), [&](size_t c) {
          appendLines(c * kChunk, std::min(array.size(), (c + 1) * kChunk), chunks[c],
                      [&](size_t i) { return panelEntry(structure, i, placements, true).dump(); });
        });
        for (const std::string& chunk : chunks) text += chunk;
      });
  out.text = manifestText(manifest);
  return out;
}

}  // namespace rotafab::jobs
