#include "jobs/Manifest.h"
#include "jobs/ManifestSteps.h"

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
#include "toolpath/ManifestFile.h"

namespace rotafab::jobs {

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
    // A band with no room for a hole, glued as --glue-narrow asks.
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

}  // namespace

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

std::string headline(const nlohmann::ordered_json& manifest) {
  const size_t sheets = manifest.at("sheets").size();
  const size_t panels = manifest.at("panels").size();
  const int fasteners = manifest.at("fasteners").get<int>();
  return fmt::format("{} structure, {} panel{} on {} sheet{}, {} fastener{}",
                     manifest.at("structure").get<std::string>(), panels, panels == 1 ? "" : "s", sheets,
                     sheets == 1 ? "" : "s", fasteners, fasteners == 1 ? "" : "s");
}

// What the builders should know before they start, from the manifest's
// optional keys: how the mesh was repaired and remeshed, and whether the
// structure will stand or must be hung. One sentence each.
core::LengthUnit displayUnitOf(const nlohmann::ordered_json& manifest) {
  const auto shown = manifest.find("display_units");
  if (shown == manifest.end() || !shown->is_string()) return {};
  return core::LengthUnit::named(shown->get<std::string>()).value_or(core::LengthUnit());
}

std::vector<std::string> buildNotes(const nlohmann::ordered_json& manifest, core::LengthUnit unit) {
  std::vector<std::string> notes;
  if (manifest.contains("cost"))
    notes.push_back(fmt::format("It takes {}.", costLine(costFromJson(manifest.at("cost")), unit)));
  if (manifest.contains("repairs")) {
    for (const auto& repair : manifest.at("repairs")) {
      geometry::MeshRepair made{repair.at("kind").get<std::string>(), repair.at("count").get<int>(),
                                repair.at("first").get<std::string>()};
      made.moved = repair.value("moved", 0.0);
      notes.push_back(fmt::format("The mesh was repaired: {}.", made.line(unit)));
    }
  }
  if (manifest.contains("simplified")) {
    const auto& simplified = manifest.at("simplified");
    // ("remeshed" is absent from the manifests of versions that simplified by collapses.)
    const bool remeshed = simplified.value("remeshed", false);
    notes.push_back(fmt::format("The mesh was {} {} faces ({} panels asked).",
                                remeshed ? "remeshed to" : "simplified to", simplified.at("faces").get<int>(),
                                simplified.at("asked").get<int>()));
  }
  if (manifest.contains("warnings")) {
    for (const auto& warning : manifest.at("warnings")) {
      notes.push_back(fmt::format("Warning: {}.", warning.get<std::string>()));
    }
  }
  if (manifest.contains("stability")) {
    const auto& stability = manifest.at("stability");
    const auto& mass = stability.at("mass_kg");
    const std::string weighs = mass.is_number() ? fmt::format(" It weighs about {:.3g} kg.", mass.get<double>()) : "";
    const double margin = stability.at("margin").get<double>();
    if (stability.at("stands").get<bool>()) {
      notes.push_back(
          fmt::format("It stands: its centre of mass is {} inside its footprint.{}", unit(margin, 2), weighs));
    } else {
      const auto point = [unit](const nlohmann::ordered_json& p) {
        return fmt::format("({}, {}, {})", unit.number(p[0].get<double>()), unit.number(p[1].get<double>()),
                           unit.number(p[2].get<double>()));
      };
      const auto& hang = stability.at("hang_points");
      const std::string from =
          hang.at(0) == hang.at(1) ? point(hang.at(0)) : point(hang.at(0)) + " and " + point(hang.at(1));
      const std::string falls =
          margin < -geometry::kBalanceInches
              ? fmt::format("It will tip over: its centre of mass is {} outside its footprint.", unit(-margin, 2))
              : std::string("It balances on the edge of its footprint, and a touch tips it.");
      notes.push_back(fmt::format("{} Hang it from {} ({}, in structure.obj's axes{}), or weight its base.{}", falls,
                                  from, unit.metric() ? "millimetres" : "inches",
                                  unit.metric() ? ", whose unit is the inch" : "", weighs));
    }
  }
  return notes;
}

std::vector<SheetKit> sheetKits(const nlohmann::ordered_json& manifest) {
  const auto& panels = manifest.at("panels");
  const size_t sheets = manifest.at("sheets").size();
  std::vector<SheetKit> kits(sheets);
  std::vector<int> held(sheets, 0);
  // The last sheet each step needs, by its panel's id (its panel's and its pieces').
  std::vector<int> needs(panels.size() + 1, 0);
  for (const auto& panel : panels) {
    const int id = panel.at("id").get<int>(), sheet = panel.at("sheet").get<int>();
    if (id < 1 || static_cast<size_t>(id) > panels.size() || sheet < 1 || static_cast<size_t>(sheet) > sheets) {
      throw std::invalid_argument(fmt::format("panel {}: no such panel or sheet", id));
    }
    int last = sheet;
    if (panel.contains("pieces")) {
      for (const auto& piece : panel.at("pieces")) last = std::max(last, piece.at("sheet").get<int>());
    }
    needs[static_cast<size_t>(id)] = last;
    SheetKit& kit = kits[static_cast<size_t>(sheet) - 1];
    kit.first = kit.first == 0 ? id : std::min(kit.first, id);
    kit.last = std::max(kit.last, id);
    ++held[static_cast<size_t>(sheet) - 1];
  }
  int done = 0;
  for (size_t s = 0; s < sheets; ++s) {
    SheetKit& kit = kits[s];
    kit.run = held[s] == 0 || kit.last - kit.first + 1 == held[s];
    while (static_cast<size_t>(done) + 1 < needs.size() &&
           needs[static_cast<size_t>(done) + 1] <= static_cast<int>(s) + 1) {
      ++done;
    }
    kit.completes = done;
  }
  return kits;
}

std::string kitText(const SheetKit& kit) {
  if (kit.first == 0) return "pieces of panels on other sheets only";
  if (kit.first == kit.last) return fmt::format("step {}", kit.first);
  return kit.run ? fmt::format("steps {}-{}", kit.first, kit.last)
                 : fmt::format("panels of steps {} to {} (not in one run)", kit.first, kit.last);
}

std::string manifestText(const nlohmann::ordered_json& manifest, std::optional<core::LengthUnit> unit) {
  try {
    std::string text =
        fmt::format("Assembly manifest: {}\n{}\n", headline(manifest), wrapped(howToJoin(manifest), 104));
    if (const auto notes = buildNotes(manifest, unit.value_or(displayUnitOf(manifest))); !notes.empty()) {
      for (const std::string& note : notes) text += note + "\n";
      text += "\n";
    }
    // Each sheet's kit: what can be built once it is cut (the dissertation's
    // V.5: builders join the panels in the order they are cut).
    const std::vector<SheetKit> kits = sheetKits(manifest);
    for (size_t s = 0; s < kits.size(); ++s) {
      const SheetKit& kit = kits[s];
      text += fmt::format("sheet {}: {}\n", s + 1,
                          kit.run && kit.first > 0
                              ? kitLine(std::pair{kit.first, kit.last}, kit.completes)
                              : fmt::format("{}; {}", kitText(kit), kitLine(std::nullopt, kit.completes)));
    }
    text += "\n";
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
    throw std::invalid_argument(
        fmt::format("the manifest is not manifest.json version 1 (docs/CONTRACT.md): {}", jsonErrorText(error)));
  }
}

}  // namespace rotafab::jobs
