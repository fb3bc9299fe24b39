#pragma once
// The assembly manifest (docs/CONTRACT.md, "manifest.json (version 1)"): what
// the builders follow, step by step in assembly order (the flood fill's,
// dissertation V.5, for bands), and what the cutter's operator needs, sheet by
// sheet. Built from a structure (geometry/Structure.h) and its sheet plan;
// printed as text (manifest.txt, `rotafab manifest`) and as a page to print.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/LengthUnit.h"
#include "core/WorkContext.h"
#include "geometry/MeshRepair.h"
#include "geometry/Remeshing.h"
#include "geometry/Stability.h"
#include "geometry/Structure.h"
#include "jobs/Part.h"
#include "jobs/SheetPlanner.h"
#include "profiles/Profiles.h"

namespace rotafab::jobs {

// A panel count asked (`--panels N`): the mesh remeshed to the faces that
// give about N panels (one a face for a band structure, one an edge for a
// woven one), or kept as drawn where it had about that many.
struct PanelCount {
  int asked = 0;  // panels
  geometry::Remeshing remeshing;
};

// The mesh as built (repaired, its holes filled if asked): the manifest's
// "mesh" counts (docs/CONTRACT.md, "manifest.json (version 1)"), and the
// repairs made to it ("repairs", named and counted).
struct BuiltMesh {
  int vertices = 0, edges = 0, faces = 0;
  std::optional<int> genus;
  std::vector<geometry::MeshRepair> repairs;
  std::optional<PanelCount> panelCount;  // when a panel count was asked
  std::optional<int> start;              // the flood fill's first face as asked, or the face it was merged into
};

// The manifest's "repairs" (docs/CONTRACT.md, "manifest.json (version 1)"):
// [{"kind", "count", "first"}], in the order made.
nlohmann::ordered_json repairsJson(const std::vector<geometry::MeshRepair>& repairs);

// The manifest's "simplified" (docs/CONTRACT.md, "manifest.json (version 1)"):
// {"asked": N panels, "faces": M, the faces the mesh was left with,
// "remeshed": whether it was remeshed, "smallest_face": the smallest face's
// area over the median's}.
nlohmann::ordered_json simplifiedJson(const PanelCount& count);

// The manifest's "stability" (docs/CONTRACT.md, "manifest.json (version 1)"):
// {"stands", "margin", "center_of_mass", "mass_kg" (null when the material's
// areal density is not known), "hang_points" (two when it does not stand, else
// empty), "footprint" (its corners on the ground)}; inches.
nlohmann::ordered_json stabilityJson(const geometry::Stability& stability);

// The unit the job's lengths are shown in: its "display_units" (an
// extension; make's --units), else inches.
core::LengthUnit displayUnitOf(const nlohmann::ordered_json& manifest);

// The assembly steps as text: for each panel in flood-fill order, its sheet,
// the panels already placed that it joins and the edge numbers to fasten
// with the fasteners of each; totals at the end; its lengths in `unit`, else
// in the manifest's "display_units". Throws std::invalid_argument naming the
// first key that is missing or wrong.
std::string manifestText(const nlohmann::ordered_json& manifest, std::optional<core::LengthUnit> unit = std::nullopt);

// manifest.json's text: a line for each member of the top level, and a line
// for each sheet and each panel (people and grep read it a panel to a line;
// indented, a large job's manifest was twice the bytes).
std::string manifestJsonText(const nlohmann::ordered_json& manifest);

// `make`'s manifest.json (docs/CONTRACT.md, "manifest.json (version 1)", for
// the structure as planned, and then the members of `more`, as
// manifestJsonText() gives it) and
// manifest.txt (manifestText()), made without the whole manifest in memory:
// the panels' lines a chunk at a time, on the context's threads (a
// 50,000-panel manifest was 660 MB). `files[s]`: the files written for
// sheet s + 1.
struct ManifestFiles {
  std::string json, text;
};
ManifestFiles manifestFiles(const geometry::Structure& structure, const BuiltMesh& mesh, const profiles::Bed& bed,
                            const SheetPlan& plan, const std::vector<std::vector<std::string>>& files,
                            const nlohmann::ordered_json& more, const core::WorkContext& context);

// The same as one HTML page, fit to print: the steps as a table, then each
// sheet (its SVG file from `folder`, inlined) on a page of its own, with
// the panels it holds in cutting order. Throws std::invalid_argument as
// manifestText(), or naming a sheet's SVG file that cannot be read.
std::string manifestHtml(const nlohmann::ordered_json& manifest, const std::filesystem::path& folder,
                         std::optional<core::LengthUnit> unit = std::nullopt);

}  // namespace rotafab::jobs
