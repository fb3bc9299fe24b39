// The DXF that CAD and laser programs import: release 12, inches, one layer
// per operation with the nearest ACI colour, and exactly the drawn geometry,
// read back both by a small reader here and by ezdxf.

#include "jobs/DxfWriter.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "SheetFixture.h"

namespace rotafab::jobs::sheet_tests {
namespace {

std::string dxfOf(const SheetDrawing& sheet) {
  std::ostringstream out;
  writeDxf(sheet, out);
  return out.str();
}

struct DxfContent {
  std::map<std::string, std::vector<std::string>> header;  // variable -> values
  std::map<std::string, int> layerColours;
  std::vector<ReadPath> paths;
  std::vector<std::string> entityTypes;
  std::vector<std::string> sections;
};

std::optional<Operation> operationOfLayer(const std::string& layer) {
  for (Operation operation : profiles::kAllOperations)
    if (dxfLayerName(operation) == layer) return operation;
  return std::nullopt;
}

// A reader for the R12 subset the writer uses: group code / value line
// pairs; HEADER variables; LAYER table entries; LINE, CIRCLE and
// POLYLINE-VERTEX-SEQEND entities.
DxfContent readDxf(const std::string& text) {
  std::vector<std::pair<int, std::string>> groups;
  std::istringstream in(text);
  for (std::string code, value; std::getline(in, code) && std::getline(in, value);)
    groups.emplace_back(std::stoi(code), value);
  EXPECT_TRUE(!groups.empty() && groups.back() == std::make_pair(0, std::string("EOF")));

  DxfContent content;
  std::string section, variable;
  for (size_t i = 0; i < groups.size(); ++i) {
    const auto& [code, value] = groups[i];
    if (code == 999) continue;
    if (code == 0 && value == "SECTION") {
      section = groups.at(++i).second;
      content.sections.push_back(section);
      continue;
    }
    if (section == "HEADER") {
      if (code == 9)
        variable = value;
      else if (code != 0)
        content.header[variable].push_back(value);
      continue;
    }
    if (code != 0) continue;
    if (value == "ENDSEC" || value == "EOF") {
      section.clear();
      continue;
    }
    // An entity or table entry: its groups run to the next group 0.
    std::map<int, std::vector<std::string>> fields;
    size_t next = i + 1;
    for (; next < groups.size() && groups[next].first != 0; ++next)
      fields[groups[next].first].push_back(groups[next].second);
    auto field = [&](int c) { return fields.count(c) ? fields[c].front() : std::string(); };
    if (section == "TABLES" && value == "LAYER") {
      content.layerColours[field(2)] = std::stoi(field(62));
    } else if (section == "ENTITIES") {
      content.entityTypes.push_back(value);
      const auto operation = operationOfLayer(field(8));
      EXPECT_TRUE(operation) << value << " on layer " << field(8);
      if (value == "LINE") {
        content.paths.push_back(
            {operation.value_or(Operation::Cut),
             {{std::stod(field(10)), std::stod(field(20))}, {std::stod(field(11)), std::stod(field(21))}},
             false});
      } else if (value == "CIRCLE") {
        ReadPath path{operation.value_or(Operation::Cut), {}, true};
        path.circle = Circle{{std::stod(field(10)), std::stod(field(20))}, std::stod(field(40))};
        content.paths.push_back(path);
      } else if (value == "POLYLINE") {
        EXPECT_EQ(field(66), "1");
        ReadPath path{operation.value_or(Operation::Cut), {}, (std::stoi(field(70)) & 1) != 0};
        // VERTEX entities up to SEQEND.
        while (next < groups.size() && groups[next] == std::make_pair(0, std::string("VERTEX"))) {
          std::map<int, std::string> vertex;
          for (++next; next < groups.size() && groups[next].first != 0; ++next)
            vertex[groups[next].first] = groups[next].second;
          EXPECT_EQ(vertex[8], field(8)) << "vertex on another layer";
          path.points.emplace_back(std::stod(vertex[10]), std::stod(vertex[20]));
        }
        EXPECT_EQ(groups.at(next), std::make_pair(0, std::string("SEQEND")));
        content.paths.push_back(path);
        ++next;
        while (next < groups.size() && groups[next].first != 0) ++next;  // SEQEND's own groups
      } else {
        ADD_FAILURE() << "unexpected entity " << value;
      }
    }
    i = next - 1;
  }
  return content;
}

TEST(DxfWriter, IsRelease12InInches) {
  const std::string text = dxfOf(sampleSheet());
  const DxfContent dxf = readDxf(text);
  EXPECT_EQ(dxf.header.at("$ACADVER"), std::vector<std::string>{"AC1009"});
  EXPECT_EQ(dxf.header.at("$MEASUREMENT"), std::vector<std::string>{"0"});
  EXPECT_EQ(dxf.header.at("$EXTMAX"), (std::vector<std::string>{"32", "18", "0"}));
  EXPECT_EQ(dxf.header.at("$LIMMAX"), (std::vector<std::string>{"32", "18"}));
  EXPECT_EQ(dxf.sections, (std::vector<std::string>{"HEADER", "TABLES", "ENTITIES"}));
  EXPECT_NE(text.find("units: inches"), std::string::npos);
  for (char c : text) ASSERT_TRUE(c == '\n' || (c >= ' ' && c <= '~')) << "byte " << int(c);
}

TEST(DxfWriter, PathsReadBackAsDrawnOnTheirLayers) {
  const SheetDrawing sheet = sampleSheet();
  const DxfContent dxf = readDxf(dxfOf(sheet));
  expectSamePaths(sheet, dxf.paths);
  // Cutting order is kept across operations.
  ASSERT_EQ(dxf.paths.size(), sheet.paths.size());
  for (size_t i = 0; i < sheet.paths.size(); ++i) EXPECT_EQ(dxf.paths[i].operation, sheet.paths[i].operation);
  // The open two-point score line is a LINE, everything else a POLYLINE.
  EXPECT_EQ(std::count(dxf.entityTypes.begin(), dxf.entityTypes.end(), "LINE"), 1);
  for (Operation operation : profiles::kAllOperations)
    EXPECT_EQ(dxf.layerColours.at(dxfLayerName(operation)), nearestAci(sheet.colours.at(operation)));
}

TEST(DxfWriter, DissertationColoursGiveTheStandardLayerColours) {
  SheetDrawing sheet = sampleSheet();
  sheet.colours = {{Operation::Cut, {0, 0, 255}},
                   {Operation::Score, {255, 0, 0}},
                   {Operation::Etch, {255, 255, 0}},
                   {Operation::Outline, {0, 255, 0}}};
  EXPECT_EQ(readDxf(dxfOf(sheet)).layerColours,
            (std::map<std::string, int>{{"CUT", 5}, {"SCORE", 1}, {"ETCH", 2}, {"OUTLINE", 3}}));
}

TEST(DxfWriter, NearestAciColours) {
  // The dissertation's defaults land on the standard colours.
  EXPECT_EQ(nearestAci({0, 0, 255}), 5);    // cut, blue
  EXPECT_EQ(nearestAci({255, 0, 0}), 1);    // score, red
  EXPECT_EQ(nearestAci({255, 255, 0}), 2);  // etch, yellow
  EXPECT_EQ(nearestAci({0, 255, 0}), 3);    // outline, green
  EXPECT_EQ(nearestAci({0, 255, 255}), 4);
  EXPECT_EQ(nearestAci({255, 0, 255}), 6);
  EXPECT_EQ(nearestAci({0, 0, 0}), 7);        // black on paper
  EXPECT_EQ(nearestAci({255, 255, 255}), 7);  // white on screen
  EXPECT_EQ(nearestAci({128, 128, 128}), 8);
  // Between them, the palette: orange is 30, a dark blue 174.
  EXPECT_EQ(nearestAci({255, 127, 0}), 30);
  EXPECT_EQ(aciColour(30), (Rgb{255, 128, 0}));
  EXPECT_EQ(nearestAci({0, 0, 127}), 174);
  // Every palette entry is its own nearest (or an equal earlier one; 7 is
  // black and white).
  for (int index = 1; index <= 255; ++index) {
    const int nearest = nearestAci(aciColour(index));
    EXPECT_LE(nearest, index);
    if (nearest == 7)
      EXPECT_TRUE(aciColour(index) == (Rgb{0, 0, 0}) || aciColour(index) == (Rgb{255, 255, 255})) << index;
    else
      EXPECT_EQ(aciColour(nearest), aciColour(index)) << index;
  }
}

TEST(DxfWriter, EzdxfReadsTheSameDrawing) {
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  const auto file = dir.write("sheet.dxf", dxfOf(sheet));
  const auto script = dir.write("read.py", R"py(
import json, sys
import ezdxf
doc = ezdxf.readfile(sys.argv[1])
auditor = doc.audit()
out = {"version": doc.dxfversion, "errors": [str(e.message) for e in auditor.errors],
       "measurement": doc.header.get("$MEASUREMENT"),
       "layers": {layer.dxf.name: layer.dxf.color for layer in doc.layers}, "entities": []}
for e in doc.modelspace():
    kind = e.dxftype()
    if kind == "LINE":
        points, closed = [list(e.dxf.start)[:2], list(e.dxf.end)[:2]], False
    elif kind == "POLYLINE":
        points, closed = [list(v.dxf.location)[:2] for v in e.vertices], bool(e.is_closed)
    else:
        points, closed = [], kind == "CIRCLE"
    entity = {"type": kind, "layer": e.dxf.layer, "closed": closed, "points": points}
    if kind == "CIRCLE":
        entity["centre"], entity["radius"] = list(e.dxf.center)[:2], e.dxf.radius
    out["entities"].append(entity)
print(json.dumps(out))
)py");
  // Debian's python3-ezdxf installs for Debian's own interpreter.
  const CommandResult result = run("/usr/bin/python3 " + shellQuote(script) + " " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err << " (ezdxf is in Debian's python3-ezdxf)";
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["version"], "AC1009");
  EXPECT_EQ(json["errors"].size(), 0u) << json["errors"].dump();
  EXPECT_EQ(json["measurement"], 0);
  for (Operation operation : profiles::kAllOperations)
    EXPECT_EQ(json["layers"][dxfLayerName(operation)], nearestAci(sheet.colours.at(operation)));
  std::vector<ReadPath> paths;
  for (const auto& entity : json["entities"]) {
    const auto operation = operationOfLayer(entity["layer"]);
    ASSERT_TRUE(operation) << entity.dump();
    ReadPath path{*operation, {}, entity["closed"]};
    for (const auto& p : entity["points"]) path.points.emplace_back(p[0].get<double>(), p[1].get<double>());
    if (entity["type"] == "CIRCLE")
      path.circle = Circle{{entity["centre"][0].get<double>(), entity["centre"][1].get<double>()}, entity["radius"]};
    paths.push_back(path);
  }
  expectSamePaths(sheet, paths);
}

}  // namespace
}  // namespace rotafab::jobs::sheet_tests
