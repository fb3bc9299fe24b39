// `rotafab make MESH --structure band` and `rotafab manifest` through the built
// program: the files of docs/CONTRACT.md ("make"), manifest.json as its
// "manifest.json (version 1)" describes it, sheets Ghostscript reads, exit
// statuses and one-line errors.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "cli/CliSupport.h"
#include "geometry/io/ObjWriter.h"
#include "support/CrumpledMesh.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

// One make of the soccer ball for the tests that only read its output.
const std::filesystem::path& soccerBall() {
  static TempDir dir;
  static const bool made = [] {
    const CommandResult result = run(kCli + " make '" + (kSource / "examples/soccer-ball.obj").string() +
                                     "' --structure band --time 0.5 --out '" + dir.path().string() + "/out'");
    EXPECT_EQ(result.status, 0) << result.err;
    return true;
  }();
  EXPECT_TRUE(made);
  static const auto out = dir.path() / "out";
  return out;
}

TEST(MakeCli, WritesEveryFileOfSpec) {
  const auto out = soccerBall();
  const nlohmann::json manifest = nlohmann::json::parse(readFile(out / "manifest.json"));
  const int sheets = static_cast<int>(manifest.at("sheets").size());
  ASSERT_GE(sheets, 1);
  for (int s = 1; s <= sheets; ++s) {
    // EPS and SVG (docs/CONTRACT.md, "make"); DXF only when asked for (SheetFormatsAreThoseAskedFor).
    for (const char* extension : {"eps", "svg", "dxf"}) {
      char name[32];
      std::snprintf(name, sizeof name, "sheet-%03d.%s", s, extension);
      EXPECT_EQ(std::filesystem::is_regular_file(out / name), std::string(extension) != "dxf") << name;
    }
  }
  for (const char* name : {"manifest.txt", "structure.obj"}) EXPECT_TRUE(std::filesystem::is_regular_file(out / name));
  // Each sheet's preview, for people (not a cut file: not in "files").
  for (const auto& sheet : manifest.at("sheets")) {
    EXPECT_TRUE(std::filesystem::is_regular_file(out / sheet.at("preview").get<std::string>())) << sheet;
    for (const auto& file : sheet.at("files")) EXPECT_EQ(file.get<std::string>().find("preview"), std::string::npos);
  }
  // The cut SVG groups each panel's paths: a panel of this sheet is a group of its own.
  const std::string firstSvg = readFile(out / "sheet-001.svg");
  const int firstPanel = manifest.at("sheets")[0].at("panels")[0].get<int>();
  EXPECT_NE(firstSvg.find("<g id=\"panel-" + std::to_string(firstPanel) + "\">"), std::string::npos);
  // Ghostscript reads every sheet, and its bounding box is the bed, in points.
  for (int s = 1; s <= sheets; ++s) {
    char name[32];
    std::snprintf(name, sizeof name, "sheet-%03d.eps", s);
    const CommandResult gs = run("gs -q -dNOPAUSE -dBATCH -sDEVICE=bbox '" + (out / name).string() + "'");
    ASSERT_EQ(gs.status, 0) << gs.err;
    std::smatch box;
    ASSERT_TRUE(std::regex_search(gs.err, box, std::regex(R"(%%BoundingBox: (\d+) (\d+) (\d+) (\d+))"))) << gs.err;
    // (the bbox device rounds outwards, and a hairline reaches half its width past its path)
    EXPECT_LE(std::stoi(box[3]), 32 * 72 + 1);
    EXPECT_LE(std::stoi(box[4]), 18 * 72 + 1);
  }
  // What it takes: the sheets of the material, the fasteners of the diameter, the cutting time sheet by sheet.
  const auto& cost = manifest.at("cost");
  EXPECT_EQ(cost.at("material"), "posterboard");
  EXPECT_EQ(cost.at("sheets"), sheets);
  EXPECT_EQ(cost.at("sheet_size"), nlohmann::json::parse("[32.0, 18.0]"));
  EXPECT_EQ(cost.at("fasteners").at("count"), manifest.at("fasteners"));
  EXPECT_EQ(cost.at("fasteners").at("diameter"), 0.125);
  ASSERT_EQ(cost.at("sheet_cutting_seconds").size(), static_cast<size_t>(sheets));
  double total = 0;
  for (const auto& seconds : cost.at("sheet_cutting_seconds")) {
    EXPECT_GT(seconds.get<double>(), 0);
    total += seconds.get<double>();
  }
  EXPECT_NEAR(cost.at("cutting_seconds").get<double>(), total, 1e-6);
  EXPECT_NE(readFile(out / "manifest.txt").find("It takes " + std::to_string(sheets) + " sheet"), std::string::npos);
  // structure.obj: the 3D panels, a vertex band and the bands' triangles each.
  std::istringstream obj(readFile(out / "structure.obj"));
  int faces = 0;
  // A group per panel, in panel order, each with its vertex band and its half of each edge band.
  std::vector<std::string> groups;
  std::vector<int> facesInGroup;
  for (std::string line; std::getline(obj, line);) {
    if (line.starts_with("f ")) {
      ++faces;
      ASSERT_FALSE(facesInGroup.empty()) << "a face before the first group";
      ++facesInGroup.back();
    }
    if (line.starts_with("g ")) groups.push_back(line.substr(2)), facesInGroup.push_back(0);
  }
  EXPECT_EQ(faces, 32 + 90 * 2 * 16);  // 32 vertex bands; 90 bands on two panels, 8 segments of 2 triangles
  ASSERT_EQ(groups.size(), manifest.at("panels").size());
  for (size_t k = 0; k < groups.size(); ++k) {
    EXPECT_EQ(groups[k], "panel-" + std::to_string(manifest.at("panels")[k].at("id").get<int>()));
    // a pentagon's or hexagon's vertex band, and 5 or 6 edge bands' halves
    EXPECT_TRUE(facesInGroup[k] == 1 + 5 * 16 || facesInGroup[k] == 1 + 6 * 16) << groups[k] << ": " << facesInGroup[k];
  }
}

// No hole's centre nearer than one diameter to the outline of the part it is cut in.
void expectHolesADiameterIn(const nlohmann::json& part, const std::string& name) {
  for (const auto& hole : part.at("holes")) {
    const double d = hole.at("diameter");
    EXPECT_GE(distanceToOutline(part.at("outline"), hole.at("xy")[0], hole.at("xy")[1]), d - 1e-9)
        << name << ": a hole of edge " << hole.at("edge");
  }
}

// The kits of `make`'s default order (docs/sheets.md, "Nesting in make"):
// each sheet holds a consecutive run of the steps (panel ids), step 1 on
// sheet 1, step i of n on S sheets by sheet ceil(i S / n) + 1; each sheet's
// "kit" and "completes" (a step is done once its panel and its pieces are cut).
void expectKits(const nlohmann::json& manifest) {
  const auto& panels = manifest.at("panels");
  const int n = static_cast<int>(panels.size()), sheets = static_cast<int>(manifest.at("sheets").size());
  std::vector<int> sheetOf(static_cast<size_t>(n) + 1), needs(static_cast<size_t>(n) + 1);
  for (const auto& panel : panels) {
    const int id = panel.at("id"), sheet = panel.at("sheet");
    sheetOf[static_cast<size_t>(id)] = sheet;
    needs[static_cast<size_t>(id)] = sheet;
    if (panel.contains("pieces")) {
      for (const auto& piece : panel.at("pieces")) {
        needs[static_cast<size_t>(id)] = std::max(needs[static_cast<size_t>(id)], piece.at("sheet").get<int>());
      }
    }
  }
  EXPECT_EQ(sheetOf[1], 1) << "step 1 on sheet 1";
  for (int i = 1; i <= n; ++i) {
    if (i > 1) {
      EXPECT_GE(sheetOf[static_cast<size_t>(i)], sheetOf[static_cast<size_t>(i) - 1]) << "step " << i;
    }
    EXPECT_LE(sheetOf[static_cast<size_t>(i)], (i * sheets + n - 1) / n + 1) << "step " << i << " of " << n;
  }
  int done = 0;
  for (int s = 1; s <= sheets; ++s) {
    const auto& sheet = manifest.at("sheets").at(static_cast<size_t>(s) - 1);
    int first = n + 1, last = 0;
    for (int i = 1; i <= n; ++i) {
      if (sheetOf[static_cast<size_t>(i)] == s) first = std::min(first, i), last = std::max(last, i);
    }
    if (last > 0) {
      EXPECT_EQ(sheet.at("kit"), nlohmann::json::array({first, last})) << "sheet " << s;
    }
    while (done < n && needs[static_cast<size_t>(done) + 1] <= s) ++done;
    EXPECT_EQ(sheet.at("completes"), done) << "sheet " << s;
  }
  EXPECT_EQ(done, n);
}

// The manifest.json panels (docs/CONTRACT.md, "manifest.json (version 1)")
// of a band structure of `faceCount` faces: numbered 1..n, one per face, each
// on a sheet inside the bed's margins, outlines counter-clockwise with their
// areas, no hole nearer than a diameter to its part's outline, and every
// interior edge's holes on exactly two panels (with the pieces cut off them),
// as many on each; `interiorEdges` < 0: as many as the panels name. Every
// side's edge number is etched but for at most `unlabelled` (make warns of
// each it could not fit).
// (`splitFaces`: faces split in two, each two panels of one face)
// (`glued`: bands with no room for a hole, no holes on either copy)
void expectSpecPanels(const nlohmann::json& m, int faceCount, int interiorEdges, int unlabelled = 0, int splitFaces = 0,
                      int glued = 0) {
  const auto& panels = m.at("panels");
  ASSERT_EQ(panels.size(), static_cast<size_t>(faceCount + splitFaces));
  std::map<int, std::vector<int>> holesOfEdge;  // edge -> hole count per panel
  std::set<int> faces, onSheets, namedEdges;
  int missingLabels = 0;
  for (const auto& sheet : m.at("sheets")) {
    for (const auto& id : sheet.at("panels")) onSheets.insert(id.get<int>());
  }
  EXPECT_EQ(onSheets.size(), static_cast<size_t>(faceCount + splitFaces));
  for (size_t i = 0; i < panels.size(); ++i) {
    const auto& p = panels[i];
    EXPECT_EQ(p.at("id"), static_cast<int>(i) + 1);
    faces.insert(p.at("source").at("face").get<int>());
    // The outline: local, counter-clockwise, not closed; placed inside the bed's margins.
    const auto& outline = p.at("outline");
    ASSERT_GE(outline.size(), 3u);
    EXPECT_NE(outline.front(), outline.back());
    double twice = 0;
    const double x = p.at("placement").at("x"), y = p.at("placement").at("y");
    const double turn = p.at("placement").at("rotation").get<double>() * M_PI / 180;
    for (size_t k = 0; k < outline.size(); ++k) {
      const double ax = outline[k][0], ay = outline[k][1];
      const double bx = outline[(k + 1) % outline.size()][0], by = outline[(k + 1) % outline.size()][1];
      twice += ax * by - bx * ay;
      const double sx = x + ax * std::cos(turn) - ay * std::sin(turn),
                   sy = y + ax * std::sin(turn) + ay * std::cos(turn);
      EXPECT_GE(sx, 0.25 - 1e-3);
      EXPECT_LE(sx, 32 - 0.25 + 1e-3);
      EXPECT_GE(sy, 0.25 - 1e-3);
      EXPECT_LE(sy, 18 - 0.25 + 1e-3);
    }
    EXPECT_GT(twice, 0) << "panel " << p.at("id") << " is not counter-clockwise";
    // The outline is given to 0.0001 in, the area from the exact one.
    EXPECT_NEAR(twice / 2, p.at("area").get<double>(), 1e-3 * p.at("area").get<double>());
    std::map<int, int> mine;
    for (const auto& hole : p.at("holes")) {
      if (hole.at("edge") != 0) ++mine[hole.at("edge").get<int>()];  // 0: a piece's tab
      EXPECT_EQ(hole.at("diameter"), 0.125);
    }
    expectHolesADiameterIn(p, "panel " + p.at("id").dump());
    if (p.contains("pieces")) {
      for (const auto& piece : p.at("pieces")) {
        for (const auto& hole : piece.at("holes"))
          if (hole.at("edge") != 0) ++mine[hole.at("edge").get<int>()];
        expectHolesADiameterIn(piece, "piece " + piece.at("name").get<std::string>());
      }
    }
    for (const auto& edge : p.at("edges")) namedEdges.insert(edge.get<int>());
    for (auto [edge, count] : mine) holesOfEdge[edge].push_back(count);
    EXPECT_EQ(p.at("neighbors").size(), p.at("edges").size());
    // On the panel, or on the piece its band was cut off as with a tab (the
    // manifest does not list a piece's labels).
    int edgeLabels = 0;
    for (const auto& label : p.at("labels")) edgeLabels += label.at("role") == "edge";
    if (p.contains("pieces")) {
      for (const auto& piece : p.at("pieces")) edgeLabels += piece.value("fastened", "tab") != "band";
    }
    EXPECT_LE(edgeLabels, static_cast<int>(p.at("edges").size()));
    missingLabels += static_cast<int>(p.at("edges").size()) - edgeLabels;
  }
  EXPECT_LE(missingLabels, unlabelled);
  EXPECT_EQ(faces.size(), static_cast<size_t>(faceCount));
  EXPECT_EQ(holesOfEdge.size() + glued, interiorEdges < 0 ? namedEdges.size() : static_cast<size_t>(interiorEdges));
  for (const auto& [edge, counts] : holesOfEdge) {
    ASSERT_EQ(counts.size(), 2u) << "edge " << edge;
    EXPECT_EQ(counts[0], counts[1]) << "edge " << edge;
  }
}

// --formats chooses the sheet files, and the manifest lists those; a folder
// without SVG sheets cannot be run, and says what to do; an unknown format
// is a usage error naming it.
TEST(MakeCli, SheetFormatsAreThoseAskedFor) {
  TempDir dir;
  const std::string ball = quoted(kSource / "examples/soccer-ball.obj");
  const CommandResult dxf = run(kCli + " make " + ball + " --structure band --time 0.5 --formats dxf --json --out " +
                                quoted(dir.path() / "dxf"));
  ASSERT_EQ(dxf.status, 0) << dxf.err;
  const nlohmann::json manifest = nlohmann::json::parse(readFile(dir.path() / "dxf/manifest.json"));
  for (const auto& sheet : manifest.at("sheets")) {
    ASSERT_EQ(sheet.at("files").size(), 1u) << sheet;
    const std::string file = sheet.at("files")[0];
    EXPECT_TRUE(file.ends_with(".dxf")) << file;
    EXPECT_TRUE(std::filesystem::is_regular_file(dir.path() / "dxf" / file)) << file;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "dxf/sheet-001.svg"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "dxf/sheet-001.eps"));
  const CommandResult runIt = run(kCli + " run " + quoted(dir.path() / "dxf") + " --device sim:grbl --dry-run --out " +
                                  quoted(dir.path() / "g.nc"));
  EXPECT_EQ(runIt.status, 1) << runIt.err;
  EXPECT_NE(runIt.err.find("lists no SVG sheet, which a cut is run from; make it again with svg in --formats"),
            std::string::npos)
      << runIt.err;
  const CommandResult bad =
      run(kCli + " make " + ball + " --structure band --formats svg,pdf --out " + quoted(dir.path() / "bad"));
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("--formats: 'pdf' is not a sheet format"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad"));
}

TEST(MakeCli, ManifestIsSpecsVersionOne) {
  const nlohmann::json m = nlohmann::json::parse(readFile(soccerBall() / "manifest.json"));
  EXPECT_EQ(m.at("version"), 1);
  EXPECT_EQ(m.at("structure"), "band");
  EXPECT_EQ(m.at("units"), "in");
  EXPECT_EQ(m.at("mesh"), nlohmann::json::parse(R"({"vertices":60,"edges":90,"faces":32,"genus":0})"));
  EXPECT_EQ(m.at("bed"), nlohmann::json::parse(R"({"width":32.0,"height":18.0,"margin":0.25})"));
  EXPECT_EQ(m.at("fasteners"), 180);  // two per band: 2 x 90 interior edges
  expectSpecPanels(m, 32, 90);
}

// Meshes other programs wrote (tests/data/external/README.md): Geomview's
// abstract polyhedron (faces of 4 to 7 sides, stored inside out) and CGAL's
// cube of triangles and quads (comment lines; narrow bands with one hole
// each). The mesh's numbers are those of the independent checker.
TEST(MakeCli, MeshesOtherProgramsWroteBuildEndToEnd) {
  std::map<std::string, nlohmann::json> expected;
  for (const char* list : {"meshes.json", "meshes-cgal.json"}) {
    for (const auto& entry : nlohmann::json::parse(readFile(kSource / "tests/data/external" / list))) {
      const std::string where = entry.contains("path")
                                    ? entry["path"].get<std::string>()
                                    : entry["archive"].get<std::string>() + ":" + entry["member"].get<std::string>();
      expected[where] = entry["expected"];
    }
  }
  // (the second in rows, `--layout rows`: cut in assembly order, nothing moved)
  for (const std::string& where : {std::string("/usr/share/geomview/geom/abstr.off"), cgalMesh("cube_poly.off")}) {
    SCOPED_TRACE(where);
    ASSERT_TRUE(expected.count(where));
    const nlohmann::json& mesh = expected[where];
    TempDir dir;
    const bool rows = where.ends_with("cube_poly.off");
    const CommandResult made = run(kCli + " make " + quoted(publicMesh(where)) + " --structure band --time 0 --out " +
                                   quoted(dir.path() / "out") + (rows ? " --layout rows" : ""));
    ASSERT_EQ(made.status, 0) << made.err;
    const auto m = nlohmann::json::parse(readFile(dir.path() / "out/manifest.json"));
    for (const char* key : {"vertices", "edges", "faces", "genus"})
      EXPECT_EQ(m.at("mesh").at(key), mesh.at(key)) << key;
    const int edges = mesh.at("edges");
    expectSpecPanels(m, mesh.at("faces"), edges);
    EXPECT_GE(m.at("fasteners").get<int>(), edges);
    EXPECT_LE(m.at("fasteners").get<int>(), 2 * edges);
    if (rows) {
      for (const auto& panel : m.at("panels")) EXPECT_EQ(panel.at("moved"), 0) << panel.at("id");
    }
    const CommandResult gs =
        run("gs -q -dNOPAUSE -dBATCH -sDEVICE=nullpage " + quoted(dir.path() / "out/sheet-001.eps"));
    EXPECT_EQ(gs.status, 0) << gs.err;
  }
}

// Meshes nobody here wrote, from Debian's packages and npm, through `make`
// with the default mesh options (repaired, merged, sized as make chooses),
// and through every invariant of docs/CONTRACT.md's manifest: CGAL's cow (a
// bow-tie vertex, slivers, and a panel that would overlap itself with a
// shallow vertex band), elephant (106 holes) and mushroom (open); STLs OpenSCAD and another program wrote; CGAL's
// L-shaped prism (a panel that overlaps itself at a reflex corner); CGAL's pig (45 narrow places, some mended only by
// the last resort, an edge of the ring about the band). Each is built at the default size, grown by at most
// 10%, its narrow places mended where they are (repairs in manifest.json), no band glued. Those no mend gives room
// (CGAL's triple torus, "mpi" (polygons far from planar) and anchor (slivers everywhere: too many to mend); the
// npm teapot) are refused with a size, or a fastener, that was tried, and that builds them as drawn (or, where at that
// size a panel misses the bed, the size or panel count with which make's own tries built it, mended). The layout in
// rows, at once: how fast nesting is does not matter here.
TEST(MakeCli, MeshesFromTheWildBuildWithDefaultOptions) {
  std::vector<std::string> meshes = {"/usr/share/openscad/testdata/scad/3D/features/import.stl",
                                     "/usr/share/assimp/models/STL/sphereWithHole.stl", cgalMesh("corner_poly.off"),
                                     cgalMesh("pig.off")};
  std::vector<std::string> refused = {cgalMesh("3torus.off"), cgalMesh("mpi.off"),
                                      (kSource / "tests/data/external/teapot.obj").string()};
#ifndef ROTAFAB_SANITIZED
  // The three of 2,300 to 2,900 faces take a minute or more each under the
  // sanitizers, which the smaller ones above exercise the same code with.
  for (const char* large : {"cow.off", "elephant.off", "mushroom.off"}) meshes.push_back(cgalMesh(large));
  // Its way out is found by make's own tries, which stop beginning after
  // 45 s of the clock: under the sanitizers' slowdown that time runs out first.
  refused.push_back(cgalMesh("anchor.off"));
#endif
  for (const std::string& where : refused) {
    SCOPED_TRACE(where);
    TempDir dir;
    const std::string mesh = quoted(publicMesh(where));
    const CommandResult made =
        run(kCli + " make " + mesh + " --structure band --layout rows --out " + quoted(dir.path() / "out"));
    EXPECT_EQ(made.status, 1) << made.err;
    std::smatch advice;
    ASSERT_TRUE(std::regex_search(made.err, advice,
                                  std::regex(R"((--size \d+in) or larger builds it as drawn \(tried\))"
                                             R"(|(--fastener \S+) or smaller builds it at this size \(tried)"
                                             R"(|; ((--panels \d+ ?)?(--size \d+in)?) builds it \(tried: )")))
        << made.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
    // As drawn (with --keep-faces too), or as make's own tries built it (with mends).
    const std::string option = advice[1].matched   ? advice[1].str() + " --keep-faces"
                               : advice[2].matched ? advice[2].str() + " --keep-faces"
                                                   : advice[3].str();
    const CommandResult followed = run(kCli + " make " + mesh + " --structure band --layout rows " + option +
                                       " --out " + quoted(dir.path() / "followed"));
    EXPECT_EQ(followed.status, 0) << option << ": " << followed.err;
  }
  for (const std::string& where : meshes) {
    SCOPED_TRACE(where);
    TempDir dir;
    const CommandResult made = run(kCli + " make " + quoted(publicMesh(where)) +
                                   " --structure band --layout rows --json --out " + quoted(dir.path() / "out"));
    ASSERT_EQ(made.status, 0) << made.err;
    const auto m = nlohmann::json::parse(readFile(dir.path() / "out/manifest.json"));
    std::smatch warned;
    const int unlabelled = std::regex_search(made.err, warned, std::regex(R"((\d+) labels? (is|are) not etched)"))
                               ? std::stoi(warned[1].str())
                               : 0;
    const int split = std::regex_search(made.err, warned, std::regex(R"((\d+) faces? split in two)"))
                          ? std::stoi(warned[1].str())
                          : 0;
    expectSpecPanels(m, m.at("mesh").at("faces"), -1, unlabelled, split, 0);
    EXPECT_EQ(made.err.find(" glued"), std::string::npos) << "no band glued unless asked: " << made.err;
    const double grown =
        std::regex_search(made.err, warned, std::regex(R"(\((\d+)% larger,)")) ? std::stod(warned[1].str()) : 0;
    EXPECT_LE(grown, 10) << made.err;
    EXPECT_TRUE(m.at("stability").contains("stands"));
    EXPECT_TRUE(m.at("mesh").at("genus").is_number()) << "repaired into an orientable manifold";
    if (where.ends_with("cow.off")) {
      EXPECT_EQ(m.at("repairs")[0], nlohmann::json::parse(R"({"kind":"split-bowtie","count":1,"first":"vertex 44"})"));
      ASSERT_GE(m.at("repairs").size(), 2u);
      EXPECT_EQ(m.at("repairs")[1].at("kind"), "collapse-short-edge");
      EXPECT_GT(m.at("repairs")[1].at("moved").get<double>(), 0);
      // (Its mean edge is 2 in at the default size: a sliver's edge or a neighbour's, not a part of the cow.)
      EXPECT_LT(m.at("repairs")[1].at("moved").get<double>(), 2.5) << "a sliver's edge, not a part of the cow";
    }
  }
}

// OpenSCAD's test STLs whose faces of zero area (collinear corners, as CAD
// programs write them) were refused for them: --repair auto collapses
// them, says so, and names the first by the file's facet; --repair none
// still refuses them. Their CAD slivers (fans across each flat side) leave
// most bands without room at the default size, and a thin wing's panel
// overlaps itself: refused with a panel count and a size that were tried,
// and that build them, at that size, through every invariant.
TEST(MakeCli, CadStlsFacesOfZeroAreaAreRepaired) {
  for (const char* where : {"/usr/share/openscad/testdata/stl/adns2610_dev_circuit_inv.stl",
                            "/usr/share/openscad/testdata/scad/misc/bad-stl-wing.stl"}) {
    SCOPED_TRACE(where);
    TempDir dir;
    const CommandResult made = run(kCli + " make " + quoted(publicMesh(where)) +
                                   " --structure band --layout rows --glue-narrow --out " + quoted(dir.path() / "out"));
    EXPECT_NE(made.err.find("repaired: collapsed "), std::string::npos) << made.err;
    EXPECT_NE(made.err.find(" of zero area (collinear corners) into "), std::string::npos) << made.err;
    EXPECT_NE(made.err.find("(the first: face "), std::string::npos) << made.err;
    EXPECT_EQ(made.err.find("has zero area"), std::string::npos) << made.err;
    const CommandResult refused = run(kCli + " make " + quoted(publicMesh(where)) +
                                      " --structure band --repair none --out " + quoted(dir.path() / "none"));
    EXPECT_EQ(refused.status, 1) << refused.err;
    EXPECT_NE(refused.err.find("has zero area"), std::string::npos) << refused.err;
#ifndef ROTAFAB_SANITIZED
    // (make's own tries of a way out stop beginning after 45 s of the clock,
    // which the sanitizers' slowdown spends before they reach it.)
    const CommandResult asDrawn = run(kCli + " make " + quoted(publicMesh(where)) +
                                      " --structure band --layout rows --out " + quoted(dir.path() / "default"));
    EXPECT_EQ(asDrawn.status, 1) << asDrawn.err;
    std::smatch wayOut;
    ASSERT_TRUE(std::regex_search(asDrawn.err, wayOut,
                                  std::regex(R"(; ((--panels \d+ )?--size (\d+)in) builds it \(tried: (\d+) panels)")))
        << asDrawn.err;
    const CommandResult followed =
        run(kCli + " make " + quoted(publicMesh(where)) + " --structure band --layout rows " + wayOut[1].str() +
            " --out " + quoted(dir.path() / "followed"));
    ASSERT_EQ(followed.status, 0) << wayOut[1].str() << ": " << followed.err;
    EXPECT_EQ(followed.err.find(" glued"), std::string::npos) << followed.err;
    EXPECT_EQ(followed.err.find("not etched"), std::string::npos) << followed.err;
    const auto m = nlohmann::json::parse(readFile(dir.path() / "followed/manifest.json"));
    EXPECT_EQ(m.at("panels").size(), std::stoul(wayOut[4].str()));
    if (std::string_view(where).ends_with("wing.stl")) {
      // Its mends take 14% of the panels of the count asked: remeshed again, aiming off by that share.
      ASSERT_TRUE(wayOut[2].matched) << asDrawn.err;
      const double asked = std::stod(wayOut[2].str().substr(std::string("--panels ").size()));
      EXPECT_NEAR(m.at("panels").size(), asked, 0.05 * asked) << followed.err;
      EXPECT_NE(followed.err.find(" panels as built: remeshed again, aiming at "), std::string::npos) << followed.err;
    }
    double side = 0;
    for (const auto& length : m.at("size")) side = std::max(side, length.get<double>());
    EXPECT_NEAR(side, std::stod(wayOut[3].str()), 0.01 * std::stod(wayOut[3].str()));
    // (Remeshed, a panel's source face is the input's face under its centre: several panels may share one.)
    std::set<int> sources;
    for (const auto& panel : m.at("panels")) sources.insert(panel.at("source").at("face").get<int>());
    expectSpecPanels(m, static_cast<int>(sources.size()), -1, 0,
                     static_cast<int>(m.at("panels").size() - sources.size()));
#endif
  }
}

// --glue-narrow: the bands no mend gives room are glued, as asked, and the
// steps say which joins to glue; --keep-faces mends nothing and refuses.
TEST(MakeCli, NarrowBandsAreGluedOnlyWhenAsked) {
  TempDir dir;
  // (CGAL's triple torus: 21 faces, some too narrow at the default size for any mend.)
  const std::string torus = quoted(publicMesh(cgalMesh("3torus.off")));
  const CommandResult glued = run(kCli + " make " + torus + " --structure band --layout rows --glue-narrow --out " +
                                  quoted(dir.path() / "glued"));
  ASSERT_EQ(glued.status, 0) << glued.err;
  std::smatch warned;
  ASSERT_TRUE(std::regex_search(glued.err, warned, std::regex(R"((\d+) bands? without room for a \S+ in fastener)")))
      << glued.err;
  const int count = std::stoi(warned[1].str());
  EXPECT_GT(count, 0);
  EXPECT_NE(glued.err.find("as --glue-narrow asks"), std::string::npos) << glued.err;
  const std::string steps = readFile(dir.path() / "glued/manifest.txt");
  int glueSteps = 0;
  for (size_t at = steps.find("(glue it: no room for a fastener"); at != std::string::npos;
       at = steps.find("(glue it: no room for a fastener", at + 1)) {
    ++glueSteps;
  }
  EXPECT_EQ(glueSteps, count) << "each glued band is one join, at the later of its two panels";
  const auto m = nlohmann::json::parse(readFile(dir.path() / "glued/manifest.json"));
  const int unlabelled = std::regex_search(glued.err, warned, std::regex(R"((\d+) labels? (is|are) not etched)"))
                             ? std::stoi(warned[1].str())
                             : 0;
  const int split =
      std::regex_search(glued.err, warned, std::regex(R"((\d+) faces? split in two)")) ? std::stoi(warned[1].str()) : 0;
  expectSpecPanels(m, m.at("mesh").at("faces"), -1, unlabelled, split, count);

  const CommandResult kept = run(kCli + " make " + torus + " --structure band --layout rows --keep-faces --out " +
                                 quoted(dir.path() / "kept"));
  EXPECT_EQ(kept.status, 1) << kept.err;
  EXPECT_NE(kept.err.find("(--keep-faces keeps every face)"), std::string::npos) << kept.err;
  EXPECT_EQ(kept.err.find("repaired: collapsed"), std::string::npos) << kept.err;
}

// What the plan warns of reaches the builders: manifest.json's "warnings"
// and manifest.txt, before the first step, as make said it.
TEST(MakeCli, TheWarningsReachTheManifest) {
  TempDir dir;
  const CommandResult made = run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                                 " --structure band --time 0 --out " + quoted(dir.path() / "a"));
  ASSERT_EQ(made.status, 0) << made.err;
  const auto warned = made.err.find("warning: ");
  ASSERT_NE(warned, std::string::npos) << made.err;
  const std::string said = made.err.substr(warned, made.err.find('\n', warned) - warned);
  const auto m = nlohmann::json::parse(readFile(dir.path() / "a/manifest.json"));
  ASSERT_EQ(m.at("warnings").size(), 1u) << m.at("warnings");
  const std::string warning = m.at("warnings")[0];
  EXPECT_TRUE(said.ends_with(": " + warning)) << said << " / " << warning;
  const std::string steps = readFile(dir.path() / "a/manifest.txt");
  const auto at = steps.find("Warning: " + warning + ".");
  ASSERT_NE(at, std::string::npos) << steps;
  EXPECT_LT(at, steps.find("step    1:"));
}

TEST(MakeCli, ManifestCommandPrintsTheSteps) {
  const CommandResult text = run(kCli + " manifest '" + soccerBall().string() + "'");
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("step    1: panel 1 (sheet "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("180 fasteners in all"), std::string::npos) << text.out;
  EXPECT_EQ(text.out, readFile(soccerBall() / "manifest.txt"));
  const CommandResult json = run(kCli + " manifest '" + soccerBall().string() + "' --format json");
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_EQ(nlohmann::json::parse(json.out), nlohmann::json::parse(readFile(soccerBall() / "manifest.json")));
  // HTML: the steps, then every sheet inlined as SVG, a page each.
  const CommandResult html = run(kCli + " manifest '" + soccerBall().string() + "' --format html");
  ASSERT_EQ(html.status, 0) << html.err;
  const nlohmann::json manifest = nlohmann::json::parse(readFile(soccerBall() / "manifest.json"));
  EXPECT_TRUE(html.out.starts_with("<!DOCTYPE html>"));
  size_t sections = 0, svgs = 0;
  for (size_t at = 0; (at = html.out.find("<section class=\"sheet\">", at)) != std::string::npos; ++at) ++sections;
  for (size_t at = 0; (at = html.out.find("<svg ", at)) != std::string::npos; ++at) ++svgs;
  EXPECT_EQ(sections, manifest.at("sheets").size());
  EXPECT_EQ(svgs, manifest.at("sheets").size());
  EXPECT_EQ(html.out.find("<?xml"), std::string::npos);
  EXPECT_NE(html.out.find("<div class=\"preview\">"), std::string::npos) << "the previews, made for people";
  EXPECT_NE(html.out.find("<tr><td>2</td><td>2</td>"), std::string::npos);
  EXPECT_NE(html.out.find("<p>It stands: its centre of mass is "), std::string::npos) << "before the steps, as in text";
  EXPECT_TRUE(html.out.ends_with("</html>\n"));
  TempDir dir;
  const CommandResult missing = run(kCli + " manifest '" + dir.path().string() + "'");
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find(": not an output folder of `rotafab make`: it holds no manifest.json"), std::string::npos)
      << missing.err;
}

// Kits by default (the dissertation's V.5: builders join the panels in the
// order they are cut): each sheet a consecutive run of the assembly steps,
// step 1 on sheet 1, no step later than one sheet beyond its fair share,
// each sheet's kit in manifest.json and manifest.txt; for the band and the
// weave. --order free takes the fewest sheets. A 6-panel cube's search
// stops once it finds nothing better, not at the end of the budget.
TEST(MakeCli, SheetsAreCutInKitsOfTheAssemblyOrder) {
  TempDir dir;
  const std::string ball = quoted(kSource / "examples/soccer-ball.obj");
  for (const char* structure : {"band", "weave"}) {
    SCOPED_TRACE(structure);
    const auto out = dir.path() / structure;
    const CommandResult made =
        run(kCli + " make " + ball + " --structure " + structure + " --time 6 --json --out " + quoted(out));
    ASSERT_EQ(made.status, 0) << made.err;
    const auto manifest = nlohmann::json::parse(readFile(out / "manifest.json"));
    expectKits(manifest);
    EXPECT_TRUE(nlohmann::json::parse(made.out).contains("nesting_stopped"));
    const std::string text = readFile(out / "manifest.txt");
    const auto& first = manifest.at("sheets").at(0);
    EXPECT_NE(text.find(fmt::format("sheet 1: steps 1-{}; once cut, steps 1-{} can be done",
                                    first.at("kit").at(1).get<int>(), first.at("completes").get<int>())),
              std::string::npos)
        << text;
  }
  const CommandResult free = run(kCli + " make " + ball + " --structure band --time 16 --order free --json --out " +
                                 quoted(dir.path() / "free"));
  ASSERT_EQ(free.status, 0) << free.err;
  EXPECT_EQ(nlohmann::json::parse(free.out).at("sheets"), 1);
  const CommandResult cube = run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                                 " --structure band --size 10in --json --out " + quoted(dir.path() / "cube"));
  ASSERT_EQ(cube.status, 0) << cube.err;
  const auto summary = nlohmann::json::parse(cube.out);
  EXPECT_NE(summary.at("nesting_stopped"), "time budget") << cube.out;
  EXPECT_GT(summary.at("cost").at("assembly_seconds").get<double>(), 0);
  expectKits(nlohmann::json::parse(readFile(dir.path() / "cube/manifest.json")));
}

// A cap on layouts gives the same sheets run after run; a budget spent
// before the first layout begins lays the panels out in rows, and says so.
TEST(MakeCli, ACapOnLayoutsGivesTheSameSheetsAndNoBudgetRows) {
  TempDir dir;
  const std::string ball = quoted(kSource / "examples/soccer-ball.obj");
  for (const char* out : {"a", "b"}) {
    const CommandResult made = run(kCli + " make " + ball + " --structure band --evaluations 8 --formats svg --out " +
                                   quoted(dir.path() / out));
    ASSERT_EQ(made.status, 0) << made.err;
    EXPECT_EQ(made.err.find("in rows"), std::string::npos) << made.err;
  }
  EXPECT_EQ(readFile(dir.path() / "a/sheet-001.svg"), readFile(dir.path() / "b/sheet-001.svg"));
  EXPECT_EQ(readFile(dir.path() / "a/manifest.json"), readFile(dir.path() / "b/manifest.json"));
  const CommandResult rows =
      run(kCli + " make " + ball + " --structure band --time 0 --json --out " + quoted(dir.path() / "c"));
  ASSERT_EQ(rows.status, 0) << rows.err;
  EXPECT_NE(rows.err.find("soccer-ball.obj: the time budget ran out before the first layout began: the 32 parts are "
                          "laid out in rows by their boxes"),
            std::string::npos)
      << rows.err;
  const CommandResult refused =
      run(kCli + " make " + ball + " --structure band --evaluations -1 --out " + quoted(dir.path() / "d"));
  EXPECT_EQ(refused.status, 2) << refused.err;
}

// A second make into the same folder replaces the first's files, stale sheets included;
// an open mesh is built open (boundary edges get no band) or with its holes filled.
TEST(MakeCli, ReusedFolderAndOpenMeshes) {
  TempDir dir;
  const auto out = dir.path() / "out";
  std::filesystem::create_directories(out);
  dir.write("out/sheet-009.eps", "stale");
  dir.write("out/notes.txt", "mine");
  // An open hemisphere-like cap: the soccer ball without one face.
  std::string obj = readFile(kSource / "examples/soccer-ball.obj");
  const auto lastFace = obj.rfind("\nf ");
  ASSERT_NE(lastFace, std::string::npos);
  obj.erase(lastFace + 1);
  const auto open = dir.write("open.obj", obj);
  const CommandResult kept = run(kCli + " make " + quoted(open) + " --structure band --time 0 --out " + quoted(out));
  ASSERT_EQ(kept.status, 0) << kept.err;
  EXPECT_FALSE(std::filesystem::exists(out / "sheet-009.eps"));
  EXPECT_EQ(readFile(out / "notes.txt"), "mine");
  auto manifest = nlohmann::json::parse(readFile(out / "manifest.json"));
  EXPECT_EQ(manifest.at("panels").size(), 31u);
  EXPECT_EQ(manifest.at("mesh").at("faces"), 31);
  EXPECT_LT(manifest.at("fasteners").get<int>(), 180);
  const CommandResult filled =
      run(kCli + " make " + quoted(open) + " --structure band --holes fill --time 0 --out " + quoted(out));
  ASSERT_EQ(filled.status, 0) << filled.err;
  manifest = nlohmann::json::parse(readFile(out / "manifest.json"));
  EXPECT_EQ(manifest.at("panels").size(), 32u);
  EXPECT_EQ(manifest.at("fasteners"), 180);
  int caps = 0;
  for (const auto& panel : manifest.at("panels")) caps += panel.at("source").contains("cap");
  EXPECT_EQ(caps, 1);
  const CommandResult refused =
      run(kCli + " make " + quoted(open) + " --structure band --holes error --out " + quoted(dir.path() / "x"));
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("open (1 boundary loop)"), std::string::npos) << refused.err;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << "left " << entry.path();
  }
}

// A panel split at a band (V.4): its piece is planned and cut as a part of
// its own, listed with the panel and on its sheet, and the steps say to
// fasten it first.
TEST(MakeCli, SplitPanelsComeWithTheirPieces) {
  TempDir dir;
  {
    std::ofstream obj(dir.path() / "crumpled.obj");
    geometry::writeObj(obj, crumpledTorus());
  }
  // --scale 1: the mesh is already at its size.
  const CommandResult made = run(kCli + " make " + quoted(dir.path() / "crumpled.obj") +
                                 " --structure band --scale 1 --time 0 --out " + quoted(dir.path() / "out"));
  ASSERT_EQ(made.status, 0) << made.err;
  const auto manifest = nlohmann::json::parse(readFile(dir.path() / "out/manifest.json"));
  expectKits(manifest);
  std::set<std::string> pieces, onSheets;
  for (const auto& panel : manifest.at("panels")) {
    if (!panel.contains("pieces")) continue;
    for (const auto& piece : panel.at("pieces")) {
      pieces.insert(piece.at("name").get<std::string>());
      EXPECT_GE(piece.at("sheet").get<int>(), 1);
      EXPECT_GE(piece.at("outline").size(), 3u);
    }
  }
  for (const auto& sheet : manifest.at("sheets")) {
    if (sheet.contains("pieces")) {
      for (const auto& name : sheet.at("pieces")) onSheets.insert(name.get<std::string>());
    }
  }
  ASSERT_FALSE(pieces.empty());
  EXPECT_EQ(pieces, onSheets);
  const std::string steps = readFile(dir.path() / "out/manifest.txt");
  EXPECT_NE(steps.find("first fasten piece " + *pieces.begin()), std::string::npos) << steps;
  const std::string fasteners = std::to_string(manifest.at("fasteners").get<int>()) + " fasteners in all";
  EXPECT_NE(steps.find(fasteners), std::string::npos) << steps;
}

TEST(MakeCli, JsonSummaryAndErrors) {
  TempDir dir;
  const std::string mesh = quoted(kSource / "examples/soccer-ball.obj");
  const CommandResult ok =
      run(kCli + " make " + mesh + " --structure band --time 0 --json --out '" + dir.path().string() + "/a'");
  ASSERT_EQ(ok.status, 0) << ok.err;
  const auto summary = nlohmann::json::parse(ok.out);
  EXPECT_EQ(summary.at("panels"), 32);
  EXPECT_EQ(summary.at("fasteners"), 180);
  for (const char* phase : {"import", "geometry", "nesting", "estimate", "writing"})
    EXPECT_TRUE(summary.at("seconds").contains(phase));

  const auto fails = [&](const std::string& args, int status, const std::string& says) {
    const CommandResult r = run(kCli + " make " + args + " --out '" + dir.path().string() + "/bad'");
    EXPECT_EQ(r.status, status) << args << ": " << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    // One error line (progress lines before it are "make: ..."), no stack trace.
    int errors = 0, others = 0;
    std::istringstream lines(r.err);
    for (std::string line; std::getline(lines, line);) {
      if (line.starts_with("error: "))
        ++errors;
      else if (!line.starts_with("make: ") && !line.starts_with("Run `rotafab") && !line.starts_with("note: ") &&
               !line.starts_with("warning: "))
        ++others;
    }
    EXPECT_EQ(errors, 1) << args << ": " << r.err;
    EXPECT_EQ(others, 0) << args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad")) << args << " left files behind";
  };
  fails(mesh + " --structure band --tension 1.5", 1, "tension");
  fails(mesh + " --structure band --start 32", 1, "--start 32");
  // Said at once: no size or panel count mends a bad --start, so none is tried.
  const CommandResult badStart =
      run(kCli + " make " + mesh + " --structure band --start 32 --out " + quoted(dir.path() / "bad"));
  EXPECT_EQ(badStart.err.find("tried"), std::string::npos) << badStart.err;
  fails(mesh + " --structure band --size 20in --fastener 2in", 1, "no room for a 2 in fastener hole");
  // With no size given, the ball grows by at most 10%; a fastener no band
  // has room for is not mended away (the ball would be another shape): the
  // error gives the size that was tried, and the fastener at this size, and
  // either one builds it. A size whose panels miss the bed is not offered.
  fails(mesh + " --structure band --fastener 2in", 1, "a panel is larger than the bed");
  for (const std::string& asked : {std::string("--fastener 1in"), std::string("--fastener 1in --size 12in")}) {
    SCOPED_TRACE(asked);
    const CommandResult large =
        run(kCli + " make " + mesh + " --structure band " + asked + " --out " + quoted(dir.path() / "large"));
    EXPECT_EQ(large.status, 1) << large.err;
    EXPECT_EQ(large.err.find("repaired"), std::string::npos) << large.err;
    std::smatch advice;
    ASSERT_TRUE(
        std::regex_search(large.err, advice,
                          std::regex(R"(\(nor have 89 other bands\); (--size \S+) or larger builds it as drawn )"
                                     R"(\(tried\), or (--fastener \S+) at this size)")))
        << large.err;
    const std::string size = asked.find("--size") != std::string::npos ? " --size 12in" : "";
    for (const auto& option : {advice[2].str() + size, "--fastener 1in " + advice[1].str()}) {
      const CommandResult followed = run(kCli + " make " + mesh + " --structure band --time 0 " + option + " --out " +
                                         quoted(dir.path() / "followed"));
      EXPECT_EQ(followed.status, 0) << option << ": " << followed.err;
      std::filesystem::remove_all(dir.path() / "followed");
    }
  }
  fails(mesh + " --structure band --fastener big", 1, "--fastener big");
  fails(quoted(dir.path() / "none.obj") + " --structure band", 1, "none.obj");
  fails(mesh + " --structure pleat", 2, "--structure");
}

// A broken mesh of the kind people download: two solids touching at a
// vertex (the file's vertex 2), one face given twice. By default make repairs
// it, says each repair on stderr and records it in manifest.json; with
// --repair none it refuses it and says that auto repairs it.
TEST(MakeCli, RepairsABrokenMeshAndSaysSo) {
  TempDir dir;
  const std::string mesh = quoted(dir.write("touching.off",
                                            "OFF\n8 9 0\n9 9 9\n0 0 0\n1 1 1\n1 0 0\n0 1 0\n2 2 1\n2 1 2\n1 2 2\n"
                                            "3 1 3 4\n3 1 4 2\n3 1 2 3\n3 3 2 4\n"
                                            "3 2 5 6\n3 2 6 7\n3 2 7 5\n3 5 7 6\n3 6 5 2\n"));
  const CommandResult made =
      run(kCli + " make " + mesh + " --structure band --size 12in --time 0 --json --out " + quoted(dir.path() / "a"));
  ASSERT_EQ(made.status, 0) << made.err;
  EXPECT_EQ(nlohmann::json::parse(made.out).at("panels"), 8);
  EXPECT_NE(made.err.find("repaired: dropped 1 duplicate face (the first: face 8)"), std::string::npos) << made.err;
  EXPECT_NE(made.err.find("repaired: split 1 bow-tie vertex into one copy per fan of faces (the first: vertex 2)"),
            std::string::npos)
      << made.err;
  const auto manifest = nlohmann::json::parse(readFile(dir.path() / "a/manifest.json"));
  ASSERT_TRUE(manifest.contains("repairs")) << manifest.dump();
  const auto& repairs = manifest.at("repairs");
  ASSERT_GE(repairs.size(), 2u);
  EXPECT_EQ(repairs[0], nlohmann::json({{"kind", "drop-duplicate-face"}, {"count", 1}, {"first", "face 8"}}));
  EXPECT_EQ(repairs[1], nlohmann::json({{"kind", "split-bowtie"}, {"count", 1}, {"first", "vertex 2"}}));
  EXPECT_EQ(manifest.at("mesh").at("vertices"), 8) << "the counts are of the repaired mesh";
  EXPECT_NE(readFile(dir.path() / "a/manifest.txt")
                .find("The mesh was repaired: dropped 1 duplicate face (the first: "
                      "face 8)."),
            std::string::npos);
  EXPECT_EQ(manifest.at("mesh").at("genus"), 0);

  const CommandResult refused =
      run(kCli + " make " + mesh + " --structure band --repair none --out " + quoted(dir.path() / "b"));
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("; --repair auto repairs it where it can"), std::string::npos) << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "b"));

  // inspect says what auto would do, in both forms.
  const CommandResult text = run(kCli + " inspect " + mesh);
  EXPECT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("`rotafab make` (--repair auto) would:\n  dropped 1 duplicate face"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("after which the mesh is usable (genus 0, 2 components)"), std::string::npos) << text.out;
  const auto json = nlohmann::json::parse(run(kCli + " inspect --json " + mesh).out);
  EXPECT_EQ(json.at("manifold"), false);
  EXPECT_EQ(json.at("usable_after_repair"), true);
  EXPECT_EQ(json.at("repairs").size(), 2u);
}

// An STL holds triangles only: by default make merges faces within 1 degree
// of one plane, so that a cube is 6 panels, as it was drawn, not 12.
TEST(MakeCli, AnStlCubeIsSixPanels) {
  TempDir dir;
  const double corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int triangles[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                                {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  std::string stl = "solid cube\n";
  for (const auto& t : triangles) {
    stl += "  facet normal 0 0 0\n    outer loop\n";
    for (int v : t) stl += fmt::format("      vertex {} {} {}\n", corners[v][0], corners[v][1], corners[v][2]);
    stl += "    endloop\n  endfacet\n";
  }
  const std::string mesh = quoted(dir.write("cube.stl", stl + "endsolid cube\n"));
  const CommandResult merged =
      run(kCli + " make " + mesh + " --structure band --size 8in --time 0 --json --out " + quoted(dir.path() / "a"));
  ASSERT_EQ(merged.status, 0) << merged.err;
  EXPECT_EQ(nlohmann::json::parse(merged.out).at("panels"), 6);
  EXPECT_NE(merged.err.find("merged its 12 faces into 6"), std::string::npos) << merged.err;
  const CommandResult inspected = run(kCli + " inspect " + mesh);
  EXPECT_NE(inspected.out.find("usable for `rotafab make`\n`rotafab make` merges its 12 faces into 6 (adjacent "
                               "faces within 1 degree of one plane become one panel"),
            std::string::npos)
      << inspected.out;
  const auto manifest = nlohmann::json::parse(readFile(dir.path() / "a/manifest.json"));
  EXPECT_EQ(manifest.at("mesh"), nlohmann::json({{"vertices", 8}, {"edges", 12}, {"faces", 6}, {"genus", 0}}));
  const CommandResult kept = run(kCli + " make " + mesh + " --structure band --size 8in --time 0 --json " +
                                 "--merge-coplanar 0 --out " + quoted(dir.path() / "b"));
  ASSERT_EQ(kept.status, 0) << kept.err;
  EXPECT_EQ(nlohmann::json::parse(kept.out).at("panels"), 12);
  // The file's face 1 is part of face 0 once merged: the flood fill starts there.
  const CommandResult started =
      run(kCli + " make " + mesh + " --structure band --size 8in --time 0 --start 1 --out " + quoted(dir.path() / "d"));
  ASSERT_EQ(started.status, 0) << started.err;
  EXPECT_NE(started.err.find("--start 1: face 1 is part of face 0 now, where the flood fill starts"), std::string::npos)
      << started.err;
  EXPECT_EQ(nlohmann::json::parse(readFile(dir.path() / "d/manifest.json")).at("panels")[0].at("source").at("face"), 0);
  // An STL OpenSCAD wrote (a sphere cut flat on one side: curved triangles stay, the flat ones merge).
  const CommandResult openscad =
      run(kCli + " make " + quoted(publicMesh("/usr/share/openscad/testdata/scad/3D/features/import.stl")) +
          " --structure band --layout rows --json --out " + quoted(dir.path() / "c"));
  EXPECT_EQ(openscad.status, 0) << openscad.err;
  EXPECT_NE(openscad.err.find("merged its 46 faces into 22"), std::string::npos) << openscad.err;
}

// --panels N: the bunny of 3,674 triangles remeshed to the 2,000 panels
// asked (+- 5%), its genus kept; the summary and the manifest say what was
// asked and got. A woven structure has a panel an edge: its count too.
TEST(MakeCli, ThePanelCountIsTheOneAsked) {
  TempDir dir;
  const std::string bunny = quoted(kSource / "examples/bunny.obj");
  const CommandResult made =
      run(kCli + " make " + bunny + " --structure band --panels 2000 --layout rows --json --out " +
          quoted(dir.path() / "a"));
  ASSERT_EQ(made.status, 0) << made.err;
  const auto summary = nlohmann::json::parse(made.out);
  EXPECT_NEAR(summary.at("panels").get<double>(), 2000, 100);
  EXPECT_EQ(summary.at("simplified").at("asked"), 2000);
  EXPECT_EQ(summary.at("simplified").at("faces"), summary.at("panels"));
  EXPECT_EQ(summary.at("simplified").at("remeshed"), true);
  EXPECT_GE(summary.at("simplified").at("smallest_face").get<double>(), 1.0 / 3);
  EXPECT_NE(made.err.find("remeshed from 3674 faces to 2000 even triangles"), std::string::npos) << made.err;
  const auto manifest = nlohmann::json::parse(readFile(dir.path() / "a/manifest.json"));
  EXPECT_EQ(manifest.at("simplified"), summary.at("simplified"));
  EXPECT_EQ(manifest.at("mesh").at("genus"), 0);
  EXPECT_EQ(manifest.at("mesh").at("faces"), summary.at("panels"));
  EXPECT_EQ(manifest.at("panels").size(), summary.at("panels").get<size_t>());

  // The text summary says it too; a count above the faces splits them, one
  // about the faces there are leaves the mesh as drawn.
  const CommandResult text = run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                                 " --structure band --panels 100 --time 0 --out " + quoted(dir.path() / "b"));
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("100 panels on "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("panels asked: 100; the mesh remeshed from 6 faces to 100 even triangles"), std::string::npos)
      << text.out;
  const CommandResult kept = run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                                 " --structure band --panels 6 --time 0 --out " + quoted(dir.path() / "k"));
  ASSERT_EQ(kept.status, 0) << kept.err;
  EXPECT_NE(kept.out.find("panels asked: 6; the mesh has 6 faces, kept as drawn"), std::string::npos) << kept.out;
  EXPECT_NE(kept.err.find("6 faces, within 5% of the 6 asked: kept as drawn"), std::string::npos) << kept.err;
  const CommandResult woven =
      run(kCli + " make " + bunny + " --structure weave --panels 300 --layout rows --json --out " +
          quoted(dir.path() / "w"));
  ASSERT_EQ(woven.status, 0) << woven.err;
  const auto weave = nlohmann::json::parse(woven.out);
  EXPECT_NEAR(weave.at("panels").get<double>(), 300, 15);
  EXPECT_EQ(weave.at("simplified").at("asked"), 300);
  const CommandResult bad =
      run(kCli + " make " + bunny + " --structure band --panels 2 --out " + quoted(dir.path() / "c"));
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find("--panels"), std::string::npos) << bad.err;
}

// A designer's size and panel count, kept: the bunny at 30 in with 1,000
// panels, CGAL's homer at 36 in with 600 and 800 and its elephant at 36 in
// with 600 and 800 are built at that size (within 1%) with the panels asked
// (+- 5%), every band fastened (none glued) and every label etched: a
// number too large for its band moves to the panel's body, turns across the
// band, or shrinks, and where it fits nowhere the design is mended there
// (docs/structures.md, "Size"), never left off. (The elephant's thin ears
// and tusks took the last resort of the mends, an edge about the band, and
// at 600 another sampling of its surface within 5% of the count, when this
// was written.)
TEST(MakeCli, ADesignersSizeAndPanelCountAreKeptWithEveryLabelEtched) {
  struct Design {
    std::string mesh;
    int panels;
    double size;
  };
  std::vector<Design> designs = {{(kSource / "examples/bunny.obj").string(), 1000, 30}};
#ifndef ROTAFAB_SANITIZED
  for (const auto& [mesh, panels] :
       {std::pair{"homer.off", 600}, {"homer.off", 800}, {"elephant.off", 600}, {"elephant.off", 800}}) {
    designs.push_back({cgalMesh(mesh), panels, 36});
  }
#endif
  for (const Design& design : designs) {
    SCOPED_TRACE(design.mesh);
    TempDir dir;
    const CommandResult made =
        run(kCli + " make " + quoted(publicMesh(design.mesh)) + " --structure band --panels " +
            std::to_string(design.panels) + " --size " + std::to_string(static_cast<int>(design.size)) +
            "in --layout rows --json --out " + quoted(dir.path() / "out"));
    ASSERT_EQ(made.status, 0) << made.err;
    EXPECT_EQ(made.err.find("not etched"), std::string::npos) << made.err;
    EXPECT_EQ(made.err.find(" glued"), std::string::npos) << made.err;
    const auto m = nlohmann::json::parse(readFile(dir.path() / "out/manifest.json"));
    EXPECT_NEAR(m.at("panels").size(), design.panels, 0.05 * design.panels);
    double side = 0;
    for (const auto& length : m.at("size")) side = std::max(side, length.get<double>());
    EXPECT_NEAR(side, design.size, 0.01 * design.size);
    // (Remeshed, a panel's source face is the input's face under its centre: several panels may share one.)
    std::set<int> sources;
    for (const auto& panel : m.at("panels")) sources.insert(panel.at("source").at("face").get<int>());
    const int shared = static_cast<int>(m.at("panels").size() - sources.size());
    expectSpecPanels(m, static_cast<int>(sources.size()), -1, 0, shared);
  }
}

// --size L is the largest side of what gets built (docs/CONTRACT.md,
// "Units and scale"), not of the mesh: the panels are cut back at the corners,
// so the mesh is scaled up to make structure.obj L across; the summary gives
// the three sides, as Pepakura does.
TEST(MakeCli, SizeIsTheLargestSideOfTheStructureBuilt) {
  TempDir dir;
  for (const std::filesystem::path& mesh : {kSource / "examples/cube.obj", kSource / "examples/soccer-ball.obj"}) {
    SCOPED_TRACE(mesh);
    const auto out = dir.path() / mesh.stem();
    const CommandResult made =
        run(kCli + " make " + quoted(mesh) + " --structure band --size 10in --time 0 --out " + quoted(out));
    ASSERT_EQ(made.status, 0) << made.err;
    Eigen::Vector3d low = Eigen::Vector3d::Constant(1e300), high = -low;
    std::istringstream obj(readFile(out / "structure.obj"));
    for (std::string line; std::getline(obj, line);) {
      if (!line.starts_with("v ")) continue;
      std::istringstream words(line.substr(2));
      Eigen::Vector3d p;
      words >> p.x() >> p.y() >> p.z();
      low = low.cwiseMin(p), high = high.cwiseMax(p);
    }
    EXPECT_NEAR((high - low).maxCoeff(), 10, 0.1);
    const auto size = nlohmann::json::parse(readFile(out / "manifest.json")).at("size");
    EXPECT_NEAR(std::max({size[0].get<double>(), size[1].get<double>(), size[2].get<double>()}), 10, 0.1);
    if (mesh.filename() == "cube.obj") {
      EXPECT_NE(made.out.find("built, 10 x 10 x 10 in"), std::string::npos) << made.out;
    }
  }
}

// A metric user reads millimetres (docs/CONTRACT.md, "Units and scale"):
// --units, else the user's config.yaml, else the unit --size is written in,
// else the machine's; manifest.json stays in inches and says which unit the
// people's files show.
TEST(MakeCli, LengthsAreShownInTheUnitTheUserWorksIn) {
  TempDir dir;
  const std::string cube = quoted(kSource / "examples/cube.obj");
  const auto out = dir.path() / "metric";
  const CommandResult metric =
      run(kCli + " make " + cube + " --structure band --size 150mm --time 0 --out " + quoted(out));
  ASSERT_EQ(metric.status, 0) << metric.err;
  EXPECT_NE(metric.out.find("built, 150 x 150 x 150 mm; stands: its centre of mass is 28.8 mm inside"),
            std::string::npos)
      << metric.out;
  EXPECT_NE(metric.out.find("1 sheet of posterboard (812.8 x 457.2 mm) and 24 fasteners of 3.18 mm;"),
            std::string::npos)
      << metric.out;
  EXPECT_NE(metric.err.find("nesting 6 panels on 812.8 x 457.2 mm beds"), std::string::npos) << metric.err;
  const std::string text = readFile(out / "manifest.txt");
  EXPECT_NE(text.find("It takes 1 sheet of posterboard (812.8 x 457.2 mm)"), std::string::npos) << text;
  EXPECT_NE(text.find("28.8 mm inside its footprint"), std::string::npos) << text;
  EXPECT_NE(readFile(out / "sheet-001.preview.svg").find("cube (band) - sheet 1 of 1, 812.8 x 457.2 mm</text>"),
            std::string::npos);
  const auto manifest = nlohmann::json::parse(readFile(out / "manifest.json"));
  EXPECT_EQ(manifest.at("units"), "in");
  EXPECT_EQ(manifest.at("display_units"), "mm");
  EXPECT_EQ(manifest.at("bed").at("width"), 32);
  // The manifest in the other unit, asked.
  const CommandResult inches = run(kCli + " manifest " + quoted(out) + " --units in");
  EXPECT_NE(inches.out.find("It takes 1 sheet of posterboard (32 x 18 in) and 24 fasteners of 0.125 in (3.2 mm)"),
            std::string::npos)
      << inches.out;

  // The user's setting outweighs --size's unit; --units outweighs both.
  const auto config = dir.path() / "config";
  std::filesystem::create_directories(config / "rotafab");
  dir.write("config/rotafab/config.yaml", "units: mm\n");
  const std::string withConfig = "XDG_CONFIG_HOME=" + quoted(config) + " " + kCli + " make " + cube +
                                 " --structure band --size 10in --time 0 --out ";
  const CommandResult preferred = run(withConfig + quoted(dir.path() / "preferred"));
  EXPECT_NE(preferred.out.find("built, 254 x 254 x 254 mm"), std::string::npos) << preferred.out;
  const CommandResult given = run(withConfig + quoted(dir.path() / "given") + " --units in");
  EXPECT_NE(given.out.find("built, 10 x 10 x 10 in"), std::string::npos) << given.out;
  // A setting that is not a unit: one line naming the file, the line and the key.
  dir.write("config/rotafab/config.yaml", "units: feet\n");
  const CommandResult bad = run(withConfig + quoted(dir.path() / "bad"));
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(bad.err, "error: " + (config / "rotafab/config.yaml").string() + ":1:8: units: feet: expected mm or in\n");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad"));
  // With --units given, the settings are not needed, nor read.
  const CommandResult past = run(withConfig + quoted(dir.path() / "past") + " --units in");
  EXPECT_EQ(past.status, 0) << past.err;
}

// Will it stand? The summary and the manifest say so. The bunny's centre of
// mass is checked against the area-weighted centroid of structure.obj's
// polygons (fasteners aside), its footprint against the lowest points there;
// a leaning tower tips, and the summary says where to hang it.
TEST(MakeCli, TheSummarySaysWhetherItStands) {
  TempDir dir;
  const CommandResult made =
      run(kCli + " make " + quoted(kSource / "examples/bunny.obj") +
          " --structure band --panels 2000 --layout rows --json --out " + quoted(dir.path() / "a"));
  ASSERT_EQ(made.status, 0) << made.err;
  const auto summary = nlohmann::json::parse(made.out);
  const auto manifest = nlohmann::json::parse(readFile(dir.path() / "a/manifest.json"));
  const auto& stability = manifest.at("stability");
  EXPECT_EQ(summary.at("stability"), stability);
  EXPECT_EQ(summary.at("size"), manifest.at("size"));
  EXPECT_EQ(stability.at("stands").get<bool>(), stability.at("margin").get<double>() > 0);
  EXPECT_EQ(stability.at("hang_points").size(), stability.at("stands").get<bool>() ? 0u : 2u);

  std::vector<Eigen::Vector3d> vertices;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero(), low = Eigen::Vector3d::Constant(1e300),
                  high = Eigen::Vector3d::Constant(-1e300);
  double area = 0;
  std::istringstream obj(readFile(dir.path() / "a/structure.obj"));
  for (std::string line; std::getline(obj, line);) {
    std::istringstream words(line);
    std::string kind;
    words >> kind;
    if (kind == "v") {
      Eigen::Vector3d p;
      words >> p.x() >> p.y() >> p.z();
      vertices.push_back(p);
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    } else if (kind == "f") {
      std::vector<Eigen::Vector3d> corners;
      for (std::string index; words >> index;) corners.push_back(vertices.at(std::stoi(index) - 1));
      for (size_t i = 1; i + 1 < corners.size(); ++i) {
        const double a = 0.5 * (corners[i] - corners[0]).cross(corners[i + 1] - corners[0]).norm();
        area += a;
        moment += a * (corners[0] + corners[i] + corners[i + 1]) / 3;
      }
    }
  }
  const Eigen::Vector3d centroid = moment / area;
  const auto& com = stability.at("center_of_mass");
  const Eigen::Vector3d reported(com[0].get<double>(), com[1].get<double>(), com[2].get<double>());
  EXPECT_LT((reported - centroid).norm(), 0.01 * (high - low).norm())
      << reported.transpose() << " against " << centroid.transpose();
  ASSERT_GE(stability.at("footprint").size(), 3u);
  // (structure.obj gives coordinates to 0.0001 in, as the sheets do.)
  constexpr double kObjRounding = 0.00005 + 1e-9;
  for (const auto& p : stability.at("footprint")) EXPECT_NEAR(p[1].get<double>(), low.y(), kObjRounding);
  // "size": the box of the structure as built, structure.obj's.
  for (int axis = 0; axis < 3; ++axis) {
    const double size = manifest.at("size")[axis];
    EXPECT_NEAR(high[axis] - low[axis], size, 2 * kObjRounding) << axis;
  }
  // Posterboard: 350 g/m2 and 0.4 g a fastener (profiles/materials/posterboard.yaml).
  double panelArea = 0;
  for (const auto& panel : manifest.at("panels")) panelArea += panel.at("area").get<double>();
  const double expected = (panelArea * 0.0254 * 0.0254 * 350 + manifest.at("fasteners").get<double>() * 0.4) / 1000;
  EXPECT_NEAR(stability.at("mass_kg").get<double>(), expected, 0.03 * expected);

  // A tower of 2 in leaning 3 in over its 1 in base (y up): it tips, and the summary says where to hang it.
  const auto tower = dir.write("tower.obj",
                               "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 3 4 0\nv 4 4 0\nv 4 4 1\nv 3 4 1\n"
                               "f 1 2 3 4\nf 8 7 6 5\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n");
  const CommandResult tips =
      run(kCli + " make " + quoted(tower) + " --structure band --size 15in --time 0 --out " + quoted(dir.path() / "b"));
  ASSERT_EQ(tips.status, 0) << tips.err;
  EXPECT_NE(tips.out.find("tips over: its centre of mass is "), std::string::npos) << tips.out;
  EXPECT_NE(tips.out.find(" outside its footprint; mass "), std::string::npos) << tips.out;
  EXPECT_NE(tips.out.find("; hang it from ("), std::string::npos) << tips.out;
  const auto leaning = nlohmann::json::parse(readFile(dir.path() / "b/manifest.json")).at("stability");
  // The builders read it in the assembly steps, before step 1.
  const std::string steps = readFile(dir.path() / "b/manifest.txt");
  EXPECT_LT(steps.find("It will tip over: its centre of mass is "), steps.find("step    1:")) << steps;
  EXPECT_NE(steps.find("Hang it from ("), std::string::npos) << steps;
  EXPECT_NE(readFile(dir.path() / "a/manifest.txt").find("It stands: its centre of mass is "), std::string::npos);
  EXPECT_NE(readFile(dir.path() / "a/manifest.txt").find("The mesh was remeshed to 2000 faces (2000 panels asked)."),
            std::string::npos);
  EXPECT_FALSE(leaning.at("stands").get<bool>());
  EXPECT_LT(leaning.at("margin").get<double>(), 0);
  EXPECT_EQ(leaning.at("hang_points").size(), 2u);
}

// Ctrl-C while the bunny is being nested (and SIGTERM, as a service manager
// sends it): make stops at once, says so, leaves no folder, and exits as a
// shell expects of a command a signal stopped. Started in the background by
// a shell, where SIGINT is ignored unless a program takes it itself.
TEST(MakeCli, InterruptStopsAtOnceAndWritesNothing) {
  // SIGINT in the first layout, SIGTERM while the parts' shapes are made.
  for (const auto& [signal, after] :
       {std::pair<std::string, std::string>{"INT", "nesting: first layout"}, {"TERM", "make: nesting [0-9]"}}) {
    TempDir dir;
    const auto out = dir.path() / "bunny", err = dir.path() / "err";
    // (Under AddressSanitizer, LeakSanitizer's scan of the heap at exit, 1.3 s
    // of a 1.6-s stop for the bunny's turned shapes, is not the stop the user
    // waits for; leaks are every other test's to find.)
    const CommandResult r = run("(ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" " + kCli + " make " +
                                quoted(kSource / "examples/bunny.obj") + " --structure band --out " + quoted(out) +
                                " 2> " + quoted(err) + " & pid=$!; for i in $(seq 600); do grep -q '" + after + "' " +
                                quoted(err) + " && break; sleep 0.05; done; sleep 1; start=$(date +%s%N); kill -" +
                                signal + " $pid; wait $pid; status=$?; end=$(date +%s%N); cat " + quoted(err) +
                                " >&2; echo $(( (end - start) / 1000000 )); exit $status)");
    EXPECT_EQ(r.status, signal == "INT" ? 130 : 143) << r.err;
    EXPECT_NE(r.err.find("make: stopped; nothing was written"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("error:"), std::string::npos) << r.err;
    EXPECT_LT(std::stoi(r.out), 1000 * kPromisedDelayScale) << "milliseconds from the signal to the end";
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// A large job's heap on huge pages where the kernel gives them on request
// (core/HugePageHeap.h): the program started again with glibc's tunable, and
// huge pages in its memory as it nests; not where the person refused them.
TEST(MakeCli, TheHeapIsOnHugePagesWhereTheKernelGivesThemOnRequest) {
  if (readFile("/sys/kernel/mm/transparent_hugepage/enabled").find("[madvise]") == std::string::npos) {
    GTEST_SKIP() << "the kernel's transparent huge pages are not in madvise mode";
  }
  for (const std::string tunables : {"", "glibc.malloc.hugetlb=0"}) {
    SCOPED_TRACE(tunables);
    TempDir dir;
    const auto err = dir.path() / "err";
    const CommandResult r =
        run("(env -u LD_PRELOAD GLIBC_TUNABLES=" + tunables + " " + kCli + " make " +
            quoted(kSource / "examples/bunny.obj") + " --structure band --out " + quoted(dir.path() / "bunny") +
            " 2> " + quoted(err) + " & pid=$!; for i in $(seq 600); do grep -q 'nesting: first layout' " + quoted(err) +
            " && break; sleep 0.05; done; tr '\\0' '\\n' < /proc/$pid/environ | grep '^GLIBC_TUNABLES='; "
            "grep '^AnonHugePages:' /proc/$pid/smaps_rollup; kill -INT $pid; wait $pid)");
    EXPECT_EQ(r.status, 130) << r.err;
    std::istringstream lines(r.out);
    std::string environment, label;
    long kilobytes = -1;
    lines >> environment >> label >> kilobytes;
    if (tunables.empty()) {
      EXPECT_EQ(environment, "GLIBC_TUNABLES=glibc.malloc.hugetlb=1") << r.out;
#ifndef ROTAFAB_SANITIZED  // (the sanitizer's allocator is not glibc's)
      EXPECT_GT(kilobytes, 0) << r.out;
#endif
    } else {
      EXPECT_EQ(environment, "GLIBC_TUNABLES=" + tunables) << r.out;
      EXPECT_EQ(kilobytes, 0) << r.out;
    }
  }
}

}  // namespace
}  // namespace rotafab::test
