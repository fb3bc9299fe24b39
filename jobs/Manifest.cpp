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
#include "jobs/SvgWriter.h"
#include "toolpath/JsonErrors.h"

namespace rotafab::jobs {

std::vector<Part> structureParts(const geometry::Structure& structure) {
  std::vector<Part> parts;
  const auto add = [&](const std::string& name, int order, const Polygon2& outline,
                       const std::vector<geometry::PanelHole>& holes, const std::vector<geometry::PanelLabel>& labels,
                       const std::vector<Polyline2>& scores) {
    Part part;
    part.name = name;
    part.order = order;
    part.outline = outline;
    for (const geometry::PanelHole& hole : holes) part.circles.push_back({hole.xy, hole.diameter / 2});
    for (const geometry::PanelLabel& label : labels) {
      part.etch.insert(part.etch.end(), label.strokes.begin(), label.strokes.end());
    }
    part.score = scores;
    parts.push_back(std::move(part));
  };
  // One running order: a panel, then its pieces, then the next panel (so
  // that pieces do not push later panels out of the planner's window).
  for (const auto& [i, k] : partOwners(structure)) {
    const geometry::Panel& panel = structure.panels[i];
    if (k < 0) {
      add(fmt::format("panel {}", panel.id), static_cast<int>(parts.size()), panel.outline, panel.holes, panel.labels,
          panel.scores);
    } else {
      const geometry::PanelPiece& piece = panel.pieces[k];
      add("piece " + piece.name, static_cast<int>(parts.size()), piece.outline, piece.holes, piece.labels, {});
    }
  }
  return parts;
}

std::vector<std::pair<int, int>> partOwners(const geometry::Structure& structure) {
  std::vector<std::pair<int, int>> owners;
  for (size_t i = 0; i < structure.panels.size(); ++i) {
    owners.emplace_back(static_cast<int>(i), -1);
    for (size_t k = 0; k < structure.panels[i].pieces.size(); ++k) {
      owners.emplace_back(static_cast<int>(i), static_cast<int>(k));
    }
  }
  return owners;
}

namespace {

// To the sheets' 0.0001 in (kSheetDecimals): the outlines are what the sheets
// cut, and nine more digits of each would only make the file larger.
double onGrid(double v) {
  constexpr double kScale = 10000.0;
  static_assert(kSheetDecimals == 4);
  return std::round(v * kScale) / kScale + 0.0;  // + 0.0: no "-0.0"
}
nlohmann::ordered_json point(const Point2& p) { return {onGrid(p.x()), onGrid(p.y())}; }

// SPEC's `source`: a band panel's face (a cap of --holes fill has none in
// the file), a woven panel's edge and cycle.
nlohmann::ordered_json sourceOf(const geometry::PanelSource& source) {
  if (source.edge >= 0) return {{"edge", source.edge}, {"cycle", source.cycle}};
  if (source.cap) return {{"face", nullptr}, {"cap", true}};
  return {{"face", source.face}};
}

}  // namespace

nlohmann::ordered_json repairsJson(const std::vector<geometry::MeshRepair>& repairs) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const geometry::MeshRepair& repair : repairs) {
    list.push_back({{"kind", repair.kind}, {"count", repair.count}, {"first", repair.first}});
  }
  return list;
}

nlohmann::ordered_json simplifiedJson(const geometry::Simplification& simplified) {
  return {{"asked", simplified.asked}, {"faces", simplified.facesAfter}};
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
  if (mesh.simplified) manifest["simplified"] = simplifiedJson(*mesh.simplified);
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

// One assembly step (geometry::stepsInPanelOrder) and where its panel and
// pieces are cut.
struct Step {
  geometry::AssemblyStep step;
  int sheet = 0;
  std::map<std::string, int> sheetOfPiece;  // of the pieces the step names
};

// The steps of a manifest read back: its panels in id order, as far as the
// steps need them (joins, holes' edges, pieces).
std::vector<Step> stepsOf(const nlohmann::ordered_json& manifest) {
  std::map<int, const nlohmann::ordered_json*> byId;
  for (const auto& panel : manifest.at("panels")) byId[panel.at("id").get<int>()] = &panel;
  std::vector<geometry::Panel> panels;
  std::vector<Step> steps;
  std::map<std::string, int> sheetOfPiece;
  for (const auto& [id, panel] : byId) {
    geometry::Panel read;
    read.id = id;
    Step step;
    step.sheet = panel->at("sheet").get<int>();
    std::set<int> edgesHere;  // with holes on the panel or its pieces
    for (const auto& hole : panel->at("holes")) {
      read.holes.push_back({hole.at("edge").get<int>(), Point2::Zero(), 0});
      edgesHere.insert(read.holes.back().edge);
    }
    if (panel->contains("pieces")) {
      for (const auto& piece : panel->at("pieces")) {
        geometry::PanelPiece& p = read.pieces.emplace_back();
        p.name = piece.at("name").get<std::string>();
        p.edge = piece.at("edge").get<int>();
        for (geometry::PieceFastening kind : {geometry::PieceFastening::Band, geometry::PieceFastening::Glue}) {
          if (piece.value("fastened", "tab") == geometry::fasteningName(kind)) p.fastening = kind;
        }
        for (const auto& hole : piece.at("holes")) {
          p.holes.push_back({hole.at("edge").get<int>(), Point2::Zero(), 0});
          edgesHere.insert(p.holes.back().edge);
        }
        sheetOfPiece[p.name] = piece.at("sheet").get<int>();
      }
    }
    const auto& neighbors = panel->at("neighbors");
    for (size_t j = 0; j < neighbors.size(); ++j) {
      const int other = neighbors[j].get<int>();
      // The joining edge (of a panel placed before this one): our extension
      // "edges", or else the edge whose holes both panels carry.
      int edge = 0;
      if (other < id && panel->contains("edges")) {
        edge = panel->at("edges").at(j).get<int>();
      } else if (other < id && byId.count(other)) {
        const auto look = [&](const nlohmann::ordered_json& holes) {
          for (const auto& hole : holes) {
            const int e = hole.at("edge").get<int>();
            if (e != 0 && edgesHere.count(e)) edge = e;  // 0: a tab's fastener, no edge
          }
        };
        look(byId.at(other)->at("holes"));
        if (byId.at(other)->contains("pieces")) {
          for (const auto& piece : byId.at(other)->at("pieces")) look(piece.at("holes"));
        }
      }
      read.joins.push_back({other, edge});
    }
    panels.push_back(std::move(read));
    steps.push_back(std::move(step));
  }
  const std::vector<geometry::AssemblyStep> assembly = geometry::stepsInPanelOrder(panels);
  for (size_t i = 0; i < steps.size(); ++i) {
    steps[i].step = assembly[i];
    for (const auto* pieces : {&assembly[i].pieces, &assembly[i].gluedPieces}) {
      for (const std::string& piece : *pieces) steps[i].sheetOfPiece[piece] = sheetOfPiece.at(piece);
    }
    for (const geometry::AssemblyJoin& join : assembly[i].joins) {
      for (const std::string& piece : join.pieces) steps[i].sheetOfPiece[piece] = sheetOfPiece.at(piece);
    }
  }
  return steps;
}

int fastenersOf(const Step& step) {
  int fasteners = static_cast<int>(step.step.pieces.size());  // the tabs'
  for (const geometry::AssemblyJoin& join : step.step.joins) fasteners += join.fasteners;
  return fasteners;
}

std::string describeJoins(const Step& step) {
  std::string text;
  for (const std::string& piece : step.step.pieces) {
    text += fmt::format("first fasten piece {} (sheet {}) to it at its tab; ", piece, step.sheetOfPiece.at(piece));
  }
  for (const std::string& piece : step.step.gluedPieces) {
    text += fmt::format("first glue piece {} (sheet {}) to it by its tab; ", piece, step.sheetOfPiece.at(piece));
  }
  if (step.step.joins.empty()) return text + "start here, the base";
  text += "join to ";
  for (size_t j = 0; j < step.step.joins.size(); ++j) {
    const geometry::AssemblyJoin& join = step.step.joins[j];
    // A band with no room for a hole (the structure at the largest size that fits the bed) is glued.
    text += join.fasteners == 0 ? fmt::format("{}panel {} at edge {} (glue it: no room for a fastener", j ? ", " : "",
                                              join.panel, join.edge)
                                : fmt::format("{}panel {} at edge {} ({} fastener{}", j ? ", " : "", join.panel,
                                              join.edge, join.fasteners, join.fasteners == 1 ? "" : "s");
    // The band cut across its middle: its far half goes on with the others.
    for (const std::string& piece : join.pieces) {
      text +=
          fmt::format(", through piece {} (sheet {}), the cut half of the band", piece, step.sheetOfPiece.at(piece));
    }
    text += ")";
  }
  return text;
}

// One assembly step as the builders read it, whatever the structure.
struct StepLine {
  int panel = 0, sheet = 0, fasteners = 0;
  int thread = 0;  // a woven panel's (its source's cycle); 0 for a band panel
  std::string joins;
};

// A woven structure's steps (dissertation IV.4): panel k goes over edge k,
// between the two panels under it, which overlap end to end there; a
// crossing is fastened, through both pairs of holes in its three panels,
// once the last of them is placed (geometry::weaveSteps()).
std::vector<StepLine> wovenStepLines(const nlohmann::ordered_json& manifest) {
  std::map<int, const nlohmann::ordered_json*> byId;
  for (const auto& panel : manifest.at("panels")) byId[panel.at("id").get<int>()] = &panel;
  std::map<int, std::vector<int>> panelsAt;  // edge -> the panels at its crossing, in id order
  std::map<std::string, int> sheetOfPiece;
  std::set<int> withHoles;  // crossings with holes; the others are glued
  std::vector<geometry::Panel> panels;
  for (const auto& [id, panel] : byId) {
    geometry::Panel& read = panels.emplace_back();
    read.id = id;
    std::set<int> edges;
    for (const auto& hole : panel->at("holes")) {
      read.holes.push_back({hole.at("edge").get<int>(), Point2::Zero(), 0});
      edges.insert(read.holes.back().edge);
    }
    // Extension: the pieces cut off a panel that would overlap itself.
    if (panel->contains("pieces")) {
      for (const auto& piece : panel->at("pieces")) {
        geometry::PanelPiece& p = read.pieces.emplace_back();
        p.name = piece.at("name").get<std::string>();
        sheetOfPiece[p.name] = piece.at("sheet").get<int>();
        for (const auto& hole : piece.at("holes")) {
          p.holes.push_back({hole.at("edge").get<int>(), Point2::Zero(), 0});
          edges.insert(p.holes.back().edge);
        }
      }
    }
    edges.erase(0);  // a piece's own fastener
    for (int e : edges) withHoles.insert(e);
    // The panels at each crossing, from the joins (our extension "edges"
    // names each neighbour's edge): holes or none (a glued crossing).
    const auto& neighbors = panel->at("neighbors");
    const auto& joinEdges = panel->at("edges");
    for (size_t j = 0; j < neighbors.size() && j < joinEdges.size(); ++j) {
      const int e = joinEdges[j].get<int>();
      for (int at : {id, neighbors[j].get<int>()}) {
        auto& list = panelsAt[e];
        if (std::find(list.begin(), list.end(), at) == list.end())
          list.insert(std::upper_bound(list.begin(), list.end(), at), at);
      }
    }
  }
  const auto others = [&](int edge, int except) {
    std::vector<int> list;
    for (int id : panelsAt[edge]) {
      if (id != except) list.push_back(id);
    }
    return list;
  };
  const auto named = [](const std::vector<int>& ids) {
    std::string text;
    for (size_t i = 0; i < ids.size(); ++i)
      text += fmt::format("{}{}", i == 0 ? "" : i + 1 == ids.size() ? " and " : ", ", ids[i]);
    return text;
  };
  // Per panel, the crossings it is at.
  std::map<int, std::set<int>> crossingsOf;
  for (const auto& [edge, at] : panelsAt) {
    for (int id : at) crossingsOf[id].insert(edge);
  }
  const std::vector<geometry::AssemblyStep> steps = geometry::weaveSteps(panels);
  std::vector<StepLine> lines;
  for (size_t i = 0; i < panels.size(); ++i) {
    const geometry::Panel& panel = panels[i];
    const auto& json = *byId.at(panel.id);
    StepLine line;
    line.panel = panel.id;
    line.sheet = json.at("sheet").get<int>();
    line.thread = json.at("source").value("cycle", 0);
    // Its ends: the crossings it is at, but its own.
    std::set<int> ends(crossingsOf[panel.id].begin(), crossingsOf[panel.id].end());
    ends.erase(panel.id);
    const std::vector<int> under = others(panel.id, panel.id);
    // Two panels at a crossing: this one goes under it too, at one end (a
    // single thread round a leaf face), bent round over itself.
    line.joins = under.size() == 2 ? fmt::format("over edge {}, above panels {}", panel.id, named(under))
                 : under.size() == 1
                     ? fmt::format("over edge {}, above panel {} and its own end (bend it round)", panel.id, under[0])
                     : fmt::format("over edge {}", panel.id);
    if (!ends.empty()) {
      // Along the thread: first the end it shares with the panel before it on the thread, last the one it shares
      // with the panel after it.
      std::vector<int> inOrder(ends.begin(), ends.end());
      const auto sharedWith = [&](size_t other) {
        for (int e : inOrder) {
          const auto& at = panelsAt[e];
          if (std::find(at.begin(), at.end(), panels[other].id) != at.end() && e != panels[other].id) return e;
        }
        return 0;
      };
      const auto sameThread = [&](size_t other) {
        return byId.at(panels[other].id)->at("source").value("cycle", 0) == line.thread;
      };
      int first = i > 0 && sameThread(i - 1) ? sharedWith(i - 1) : 0;
      if (first == 0 && i + 1 < panels.size() && sameThread(i + 1) && inOrder.size() == 2) {
        const int last = sharedWith(i + 1);
        first = last == inOrder[0] ? inOrder[1] : inOrder[0];
      }
      std::stable_partition(inOrder.begin(), inOrder.end(), [&](int e) { return e == first; });
      line.joins += fmt::format("; its ends under edge{} {}", inOrder.size() == 1 ? "" : "s", named(inOrder));
    }
    if (!steps[i].pieces.empty()) {
      std::string names;
      for (size_t k = 0; k < steps[i].pieces.size(); ++k) {
        names +=
            fmt::format("{}{} (sheet {})", k ? " and " : "", steps[i].pieces[k], sheetOfPiece.at(steps[i].pieces[k]));
      }
      line.joins = fmt::format("first fasten piece{} {} to it where {} overlap ({} fastener{}); ",
                               steps[i].pieces.size() == 1 ? "" : "s", names, "they", steps[i].pieces.size(),
                               steps[i].pieces.size() == 1 ? "" : "s") +
                   line.joins;
      line.fasteners += static_cast<int>(steps[i].pieces.size());
    }
    // A glued crossing (no room for a hole), at the step of its last panel.
    for (int e : ends) {
      const auto& at = panelsAt[e];
      if (!withHoles.count(e) && !at.empty() && at.back() == panel.id) {
        line.joins += fmt::format("; glue crossing {} where panels {} overlap (no room for a fastener)", e,
                                  named(std::vector<int>(at.begin(), at.end())));
      }
    }
    if (!withHoles.count(panel.id) && !panelsAt[panel.id].empty() && panelsAt[panel.id].back() == panel.id) {
      line.joins += fmt::format("; glue crossing {} where panels {} overlap (no room for a fastener)", panel.id,
                                named(panelsAt[panel.id]));
    }
    for (const geometry::AssemblyJoin& join : steps[i].joins) {
      std::vector<int> three = panelsAt[join.edge];
      // The one over it first.
      std::stable_partition(three.begin(), three.end(), [&](int id) { return id == join.edge; });
      line.joins += fmt::format("; fasten crossing {} through panels {} ({} fastener{})", join.edge, named(three),
                                join.fasteners, join.fasteners == 1 ? "" : "s");
      line.fasteners += join.fasteners;
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

std::vector<StepLine> stepLines(const nlohmann::ordered_json& manifest) {
  if (manifest.at("structure").get<std::string>() == geometry::structureName(geometry::StructureKind::Weave)) {
    return wovenStepLines(manifest);
  }
  std::vector<StepLine> lines;
  for (const Step& step : stepsOf(manifest)) {
    lines.push_back({step.step.panel, step.sheet, fastenersOf(step), 0, describeJoins(step)});
  }
  return lines;
}

// What the steps mean, for the structure.
std::string howToJoin(const nlohmann::ordered_json& manifest) {
  if (manifest.at("structure").get<std::string>() == geometry::structureName(geometry::StructureKind::Weave)) {
    return "Weave the panels in this order, thread by thread, each thread's panels one after the other along it. "
           "Each panel goes over the edge whose number is etched in its middle and under the edges numbered at its "
           "ends; the underlined number is the panel under it met first turning counter-clockwise. Where three "
           "panels carry one number, lay the panel with that number in its middle over the other two (which overlap "
           "end to end) and fasten the three through both pairs of holes. Lay each panel loosely where the steps "
           "name panels not yet placed; its crossing is fastened at the step of its last panel. The etched side "
           "faces out.";
  }
  return "Join the panels in this order (flood fill from panel 1, the base). Each edge band overlaps the band with "
         "the same number on the panel named; fasten them through their holes.";
}

// The text wrapped at `width` columns.
std::string wrapped(const std::string& text, size_t width) {
  std::string out, line;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && line.size() + 1 + word.size() > width) out += line + "\n", line.clear();
    line += (line.empty() ? "" : " ") + word;
    start = end + 1;
  }
  return out + line + "\n";
}

std::string headline(const nlohmann::ordered_json& manifest) {
  const size_t sheets = manifest.at("sheets").size();
  const size_t panels = manifest.at("panels").size();
  const int fasteners = manifest.at("fasteners").get<int>();
  return fmt::format("{} structure, {} panel{} on {} sheet{}, {} fastener{}",
                     manifest.at("structure").get<std::string>(), panels, panels == 1 ? "" : "s", sheets,
                     sheets == 1 ? "" : "s", fasteners, fasteners == 1 ? "" : "s");
}

// What the builders should know before they start, from the manifest's
// optional keys: how the mesh was repaired and simplified, and whether the
// structure will stand or must be hung. One sentence each.
std::vector<std::string> buildNotes(const nlohmann::ordered_json& manifest) {
  std::vector<std::string> notes;
  if (manifest.contains("cost"))
    notes.push_back(fmt::format("It takes {}.", costLine(costFromJson(manifest.at("cost")))));
  if (manifest.contains("repairs")) {
    for (const auto& repair : manifest.at("repairs")) {
      const geometry::MeshRepair made{repair.at("kind").get<std::string>(), repair.at("count").get<int>(),
                                      repair.at("first").get<std::string>()};
      notes.push_back(fmt::format("The mesh was repaired: {}.", made.line()));
    }
  }
  if (manifest.contains("simplified")) {
    const auto& simplified = manifest.at("simplified");
    notes.push_back(fmt::format("The mesh was simplified to {} faces ({} panels asked).",
                                simplified.at("faces").get<int>(), simplified.at("asked").get<int>()));
  }
  if (manifest.contains("stability")) {
    const auto& stability = manifest.at("stability");
    const auto& mass = stability.at("mass_kg");
    const std::string weighs = mass.is_number() ? fmt::format(" It weighs about {:.3g} kg.", mass.get<double>()) : "";
    const double margin = stability.at("margin").get<double>();
    if (stability.at("stands").get<bool>()) {
      notes.push_back(
          fmt::format("It stands: its centre of mass is {:.2f} in inside its footprint.{}", margin, weighs));
    } else {
      const auto point = [](const nlohmann::ordered_json& p) {
        return fmt::format("({:.2f}, {:.2f}, {:.2f})", p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
      };
      const auto& hang = stability.at("hang_points");
      const std::string from =
          hang.at(0) == hang.at(1) ? point(hang.at(0)) : point(hang.at(0)) + " and " + point(hang.at(1));
      const std::string falls =
          margin < -geometry::kBalanceInches
              ? fmt::format("It will tip over: its centre of mass is {:.2f} in outside its footprint.", -margin)
              : std::string("It balances on the edge of its footprint, and a touch tips it.");
      notes.push_back(
          fmt::format("{} Hang it from {} (inches, as in structure.obj), or weight its base.{}", falls, from, weighs));
    }
  }
  return notes;
}

}  // namespace

std::string manifestText(const nlohmann::ordered_json& manifest) {
  try {
    std::string text =
        fmt::format("Assembly manifest: {}\n{}\n", headline(manifest), wrapped(howToJoin(manifest), 104));
    if (const auto notes = buildNotes(manifest); !notes.empty()) {
      for (const std::string& note : notes) text += note + "\n";
      text += "\n";
    }
    int total = 0, thread = 0;
    for (const StepLine& step : stepLines(manifest)) {
      total += step.fasteners;
      if (step.thread != thread) text += fmt::format("{}thread {}:\n", thread == 0 ? "" : "\n", step.thread);
      thread = step.thread;
      text += fmt::format("step {:>4}: panel {} (sheet {}): {}\n", step.panel, step.panel, step.sheet, step.joins);
    }
    text += fmt::format("\n{} fastener{} in all\n", total, total == 1 ? "" : "s");
    return text;
  } catch (const nlohmann::json::exception& error) {
    throw std::invalid_argument(fmt::format("the manifest is not SPEC's version 1: {}", jsonErrorText(error)));
  }
}

std::string manifestHtml(const nlohmann::ordered_json& manifest, const std::filesystem::path& folder) {
  try {
    std::string html = fmt::format(R"(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>Assembly manifest: {0}</title>
<style>
body {{ font-family: sans-serif; margin: 2em; }}
table {{ border-collapse: collapse; }}
td, th {{ border: 1px solid #999; padding: 0.2em 0.6em; text-align: left; vertical-align: top; }}
section.sheet {{ break-before: page; }}
section.sheet svg {{ width: 100%; height: auto; border: 1px solid #ccc; }}
section.sheet .cutfile svg path {{ vector-effect: non-scaling-stroke; stroke-width: 1px; }}
section.sheet .cutfile svg #etch path {{ stroke: #a0522d; }}
@media print {{ body {{ margin: 0; }} }}
</style>
</head>
<body>
<h1>Assembly manifest</h1>
<p>{0}. {1}</p>
<table>
<tr><th>step</th><th>panel</th><th>sheet</th><th>joins</th><th>fasteners</th></tr>
)",
                                   xmlText(headline(manifest)), xmlText(howToJoin(manifest)));
    for (const std::string& note : buildNotes(manifest)) html += fmt::format("<p>{}</p>\n", xmlText(note));
    int total = 0;
    for (const StepLine& step : stepLines(manifest)) {
      total += step.fasteners;
      html += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n", step.panel, step.panel,
                          step.sheet, xmlText(step.joins), step.fasteners);
    }
    html += fmt::format("</table>\n<p>{} fastener{} in all.</p>\n", total, total == 1 ? "" : "s");
    for (const auto& sheet : manifest.at("sheets")) {
      // The preview, made for people; else (a manifest from before previews) the cut file, restyled.
      std::string svgFile;
      for (const auto& file : sheet.at("files")) {
        const auto name = file.get<std::string>();
        if (name.ends_with(".svg")) svgFile = name;
      }
      const bool preview = sheet.contains("preview");
      if (preview) svgFile = sheet.at("preview").get<std::string>();
      std::string panels;
      for (const auto& id : sheet.at("panels")) panels += (panels.empty() ? "" : ", ") + std::to_string(id.get<int>());
      html += fmt::format("<section class=\"sheet\">\n<h2>Sheet {}</h2>\n<p>Panels, in cutting order: {}</p>\n",
                          sheet.at("index").get<int>(), panels);
      if (!svgFile.empty()) {
        std::ifstream in(folder / svgFile);
        if (!in) throw std::invalid_argument(fmt::format("{}: cannot read it", (folder / svgFile).string()));
        std::string svg{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        if (svg.starts_with("<?xml")) svg.erase(0, svg.find('\n') + 1);  // no declaration inside HTML
        html += fmt::format("<div class=\"{}\">\n{}</div>\n", preview ? "preview" : "cutfile", svg);
      }
      html += "</section>\n";
    }
    html += "</body>\n</html>\n";
    return html;
  } catch (const nlohmann::json::exception& error) {
    throw std::invalid_argument(fmt::format("the manifest is not SPEC's version 1: {}", jsonErrorText(error)));
  }
}

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
