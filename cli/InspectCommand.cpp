#include "cli/InspectCommand.h"

#include <fmt/format.h>

#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/ExitStatus.h"
#include "geometry/CoplanarMerge.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshRepair.h"
#include "geometry/io/MeshImport.h"
#include "jobs/MakeJob.h"
#include "jobs/Manifest.h"

namespace rotafab::cli {
namespace {

struct InspectOptions {
  std::string mesh;
  bool json = false;
};

nlohmann::ordered_json topologyJson(const geometry::MeshTopology& t) {
  return {{"vertices", t.vertices},
          {"edges", t.edges},
          {"faces", t.faces},
          {"boundary_loops", t.boundaryLoops},
          {"components", t.components},
          {"euler", t.euler},
          {"genus", t.genus ? nlohmann::ordered_json(*t.genus) : nlohmann::ordered_json(nullptr)},
          {"orientable", t.orientable},
          {"manifold", t.manifold}};
}

// The problem kinds for --json, named as the repairs are.
const char* problemKindName(geometry::MeshProblemKind kind) {
  switch (kind) {
    case geometry::MeshProblemKind::RepeatedCorner:
      return "repeated-corner";
    case geometry::MeshProblemKind::ZeroAreaFace:
      return "zero-area-face";
    case geometry::MeshProblemKind::NonManifoldEdge:
      return "non-manifold-edge";
    case geometry::MeshProblemKind::BowTieVertex:
      return "bow-tie-vertex";
    case geometry::MeshProblemKind::NonOrientable:
      return "non-orientable";
  }
  return "other";
}

void printRepairPreview(const geometry::RepairPreview& preview) {
  if (preview.repairs.empty()) {
    fmt::print("`rotafab make` (--repair auto) has nothing to repair here; it refuses this mesh too\n");
    return;
  }
  fmt::print("`rotafab make` (--repair auto) would:\n");
  for (const auto& repair : preview.repairs) fmt::print("  {}\n", repair.line());
  if (preview.after.usable()) {
    const auto& after = preview.after.topology;
    fmt::print("after which the mesh is usable (genus {}, {} component{})\n",
               after.genus ? std::to_string(*after.genus) : "undefined", after.components,
               after.components == 1 ? "" : "s");
  } else {
    fmt::print("and still refuse it: {}\n", preview.after.problems.front().message);
  }
}

// What make's default coplanar merge does to the mesh (an STL's), if anything.
void printMergePreview(const std::string& name, geometry::PolygonMesh mesh) {
  const double degrees = jobs::defaultMergeDegrees(name);
  if (!(degrees > 0)) return;
  const geometry::CoplanarMerge merged = geometry::mergeCoplanarFaces(mesh, degrees);
  if (merged.regions == 0) return;
  fmt::print(
      "`rotafab make` merges its {} faces into {} (adjacent faces within {:g} degree of one plane become one "
      "panel; --merge-coplanar 0 keeps them apart)\n",
      merged.facesBefore, merged.facesAfter, degrees);
}

void printText(const std::string& name, const geometry::PolygonMesh& mesh, const geometry::MeshAnalysis& analysis,
               const geometry::RepairPreview& preview) {
  const auto& t = analysis.topology;
  std::map<size_t, int> sides;
  for (const auto& face : mesh.faces) ++sides[face.size()];
  std::string histogram;
  for (auto [n, count] : sides) {
    const std::string kind = n == 3 ? "triangle" : n == 4 ? "quad" : fmt::format("{}-gon", n);
    histogram += fmt::format("{}{} {}{}", histogram.empty() ? "" : ", ", count, kind, count == 1 ? "" : "s");
  }
  fmt::print("{}\n", name);
  fmt::print("  vertices        {}\n", t.vertices);
  fmt::print("  edges           {}\n", t.edges);
  fmt::print("  faces           {} ({})\n", t.faces, histogram);
  fmt::print("  boundary loops  {}\n", t.boundaryLoops);
  fmt::print("  components      {}\n", t.components);
  fmt::print("  Euler char.     {}\n", t.euler);
  fmt::print("  genus           {}\n", t.genus ? std::to_string(*t.genus) : "undefined (not an orientable manifold)");
  fmt::print("  orientable      {}\n", t.orientable ? "yes" : "no");
  fmt::print("  manifold        {}\n", t.manifold ? "yes" : "no");
  for (const auto& note : analysis.notes) fmt::print("  repaired: {}\n", note);
  if (analysis.usable()) {
    fmt::print("usable for `rotafab make`\n");
    printMergePreview(name, mesh);
    return;
  }
  constexpr size_t kShown = 20;
  fmt::print("{} problem{} (`rotafab make --repair none` refuses this mesh):\n", analysis.problems.size(),
             analysis.problems.size() == 1 ? "" : "s");
  for (size_t i = 0; i < analysis.problems.size() && i < kShown; ++i)
    fmt::print("  {}\n", analysis.problems[i].message);
  if (analysis.problems.size() > kShown) fmt::print("  ... and {} more\n", analysis.problems.size() - kShown);
  printRepairPreview(preview);
}

int runInspect(const InspectOptions& options) {
  try {
    geometry::ImportedMesh imported = geometry::importMesh(options.mesh);
    for (const auto& warning : imported.warnings) fmt::print(stderr, "warning: {}: {}\n", options.mesh, warning);
    const geometry::RepairPreview preview = geometry::previewRepair(imported.mesh);
    const geometry::MeshAnalysis analysis = geometry::analyzeMesh(imported.mesh);
    if (options.json) {
      for (const auto& note : analysis.notes) fmt::print(stderr, "note: {}: {}\n", options.mesh, note);
      nlohmann::ordered_json object = topologyJson(analysis.topology);
      // What the text lists, all of it (the text shows the first 20).
      object["usable"] = analysis.usable();
      object["problems"] = nlohmann::ordered_json::array();
      for (const auto& problem : analysis.problems) {
        object["problems"].push_back({{"kind", problemKindName(problem.kind)}, {"message", problem.message}});
      }
      object["repaired"] = analysis.notes;
      if (!analysis.usable()) {
        object["repairs"] = jobs::repairsJson(preview.repairs);
        object["usable_after_repair"] = preview.after.usable();
      }
      std::cout << object.dump() << '\n';
    } else {
      printText(options.mesh, imported.mesh, analysis, preview);
    }
    return kSuccess;
  } catch (const geometry::InvalidMeshError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "error: {}: the mesh does not fit in memory\n", options.mesh);
    return kUserError;
  } catch (const std::exception& error) {
    fmt::print(stderr, "error: {}: {}\n", options.mesh, error.what());
    return kUserError;
  }
}

}  // namespace

void addInspectCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<InspectOptions>();
  CLI::App* inspect = app.add_subcommand("inspect", "Read a mesh and report its topology and any problems");
  inspect->add_option("MESH", options->mesh, "Mesh file: OBJ, OFF, PLY, STL, glTF/GLB, 3MF, or any format Assimp reads")
      ->required();
  inspect->add_flag("--json", options->json,
                    "Print one JSON object: vertices, edges, faces, boundary_loops, components, euler, genus, "
                    "orientable, manifold; for a broken mesh also repairs (what `make --repair auto` would do) and "
                    "usable_after_repair");
  inspect->footer(
      "Counts are of the mesh as imported and cleaned: vertices at identical positions welded, faces with fewer than "
      "3\n"
      "distinct vertices and unreferenced vertices dropped. A readable but broken mesh is reported (exit 0) with its\n"
      "problems listed; an unreadable file is refused (exit 1).\n\n"
      "Examples:\n"
      "  rotafab inspect examples/bunny.obj\n"
      "  rotafab inspect examples/torus.obj --json");
  inspect->callback([options, &status] { status = runInspect(*options); });
}

}  // namespace rotafab::cli
