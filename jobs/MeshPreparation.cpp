#include "jobs/MakeSteps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <functional>
#include <regex>

#include "core/UserError.h"
#include "geometry/BandStructure.h"
#include "geometry/ConstructionScale.h"
#include "geometry/CoplanarMerge.h"
#include "geometry/EdgeProjection.h"
#include "geometry/FastenerHoles.h"
#include "geometry/HoleFilling.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshRepair.h"
#include "geometry/Remeshing.h"
#include "geometry/WeaveStructure.h"
#include "geometry/io/MeshImport.h"

namespace rotafab::jobs {
namespace {

// An STL holds triangles only: its planar faces come back as one face each
// when their triangles lie within this angle of one plane.
constexpr double kStlMergeDegrees = 1.0;

}  // namespace

double defaultMergeDegrees(const std::filesystem::path& mesh) {
  std::string extension = mesh.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return extension == ".stl" ? kStlMergeDegrees : 0.0;
}

namespace making {
namespace {

using geometry::Parameter;

// --panels N: the mesh remeshed to even triangles that give about N panels
// (after the merge of coplanar faces and the filling of holes, so that the
// count is the one built), its topology checked to be the same. A band
// structure has a panel a face; a woven one a panel an edge, and a closed
// triangle mesh has 3/2 edges a face.
PanelCount remeshedMesh(const MakeRequest& request, geometry::PolygonMesh& mesh, geometry::MeshAnalysis& analysis,
                        const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  const geometry::MeshTopology before = analysis.topology;
  PanelCount count;
  count.asked = *request.panels;
  const bool woven = request.structure == geometry::StructureKind::Weave;
  const int faces = request.remeshFaces.value_or(
      woven ? std::max(1, static_cast<int>(std::lround(count.asked * 2.0 / 3.0))) : count.asked);
  try {
    count.remeshing = geometry::remeshEvenly(mesh, faces, context);
  } catch (const geometry::InvalidMeshError& error) {
    throw core::UserError(fmt::format("{}: {}", name, error.what()));
  } catch (const std::invalid_argument& error) {
    throw core::UserError(
        fmt::format("{}: {} {}: {}", name, request.names(Parameter::Panels), *request.panels, error.what()));
  }
  const geometry::Remeshing& remeshing = count.remeshing;
  if (!remeshing.remeshed) {
    context.note(fmt::format("{}: {} faces, within {:g}% of the {} asked: kept as drawn", name, remeshing.facesBefore,
                             100 * geometry::kKeptAsDrawn, remeshing.asked));
    return count;
  }
  analysis = geometry::analyzeMesh(mesh);
  const geometry::MeshTopology& after = analysis.topology;
  if (after.genus != before.genus || after.components != before.components ||
      after.boundaryLoops != before.boundaryLoops || !analysis.problems.empty()) {
    // No collapse breaks the link condition; this is the proof.
    std::string what;
    if (!analysis.problems.empty()) {
      what = analysis.problems.front().message;
    } else if (after.genus != before.genus) {
      const auto genus = [](const std::optional<int>& g) { return g ? std::to_string(*g) : std::string("none"); };
      what = fmt::format("genus {}, not {}", genus(after.genus), genus(before.genus));
    } else if (after.components != before.components) {
      what = fmt::format("{} parts, not {}", after.components, before.components);
    } else {
      what = fmt::format("{} boundary loops, not {}", after.boundaryLoops, before.boundaryLoops);
    }
    throw core::UserError(
        fmt::format("{}: remeshed to {} faces it would not keep its topology ({}); build it without {}", name,
                    remeshing.facesAfter, what, request.names(Parameter::Panels)));
  }
  const double diagonal = geometry::boundingBoxDiagonal(mesh);
  context.note(fmt::format(
      "{}: remeshed from {} faces to {} even triangles{}, keeping its genus, boundary{} (the surface within {:.2g}% "
      "of its size; the smallest face {:.0f}% of the median's)",
      name, remeshing.facesBefore, remeshing.facesAfter,
      woven                 ? fmt::format(" ({} panels asked, one an edge)", count.asked)
      : request.remeshFaces ? fmt::format(" ({} asked, aiming at {})", count.asked, faces)
                            : fmt::format(" ({} asked)", count.asked),
      remeshing.creaseEdges > 0 ? fmt::format(" and {} crease edges", remeshing.creaseEdges) : "",
      diagonal > 0 ? 100 * remeshing.largestMove / diagonal : 0.0, 100 * remeshing.smallestAreaRatio));
  return count;
}

}  // namespace

geometry::PolygonMesh importedMesh(const MakeRequest& request, BuiltMesh& counts, const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  context.report({"import", "", 0, 0});
  geometry::ImportedMesh imported = geometry::importMesh(request.mesh, &context.cancellation());
  for (const auto& warning : imported.warnings) context.warn(fmt::format("{}: {}", name, warning));
  geometry::PolygonMesh& mesh = imported.mesh;
  std::vector<geometry::MeshRepair> repairs;
  if (request.repair) {
    repairs = geometry::repairMesh(mesh);
    for (const auto& repair : repairs)
      context.note(fmt::format("{}: repaired: {}", name, repair.line(request.shownIn)));
  }
  geometry::MeshAnalysis analysis = geometry::analyzeMesh(mesh);
  for (const auto& note : analysis.notes) context.note(fmt::format("{}: {}", name, note));
  if (const geometry::MeshRepair oriented = geometry::orientRepair(analysis, mesh); oriented.count > 0) {
    repairs.push_back(oriented);
  }
  try {
    geometry::requireUsable(analysis);
  } catch (const geometry::InvalidMeshError& error) {
    throw core::UserError(fmt::format(
        "{}: {}{}", name, error.what(),
        request.repair ? "" : fmt::format("; {} auto repairs it where it can", request.names(Parameter::Repair))));
  }
  std::optional<int> start = request.start;
  const double mergeDegrees = request.mergeCoplanar.value_or(defaultMergeDegrees(request.mesh));
  if (mergeDegrees > 0) {
    const geometry::CoplanarMerge merged = geometry::mergeCoplanarFaces(mesh, mergeDegrees);
    if (const auto into = merged.mergedInto.find(request.start.value_or(-1)); into != merged.mergedInto.end()) {
      start = into->second;
      context.note(fmt::format("{}: {} {}: face {} is part of face {} now, where the flood fill starts", name,
                               request.names(Parameter::Start), *request.start, *request.start, *start));
    }
    if (merged.regions > 0) {
      context.note(
          fmt::format("{}: merged its {} faces into {}, adjacent faces within {:g} degree{} of one plane "
                      "becoming one ({} 0 keeps them apart)",
                      name, merged.facesBefore, merged.facesAfter, mergeDegrees, mergeDegrees == 1 ? "" : "s",
                      request.names(Parameter::MergeCoplanar)));
      analysis = geometry::analyzeMesh(mesh);
      try {
        geometry::requireUsable(analysis);
      } catch (const geometry::InvalidMeshError& error) {
        throw core::UserError(fmt::format("{}: with its coplanar faces merged: {}; {} 0 keeps them apart", name,
                                          error.what(), request.names(Parameter::MergeCoplanar)));
      }
    }
  }
  if (const int loops = analysis.topology.boundaryLoops; loops > 0) {
    if (request.holes == HolesMode::Error) {
      // (A weave crosses every edge: a boundary edge has no second side to cross to.)
      throw core::UserError(
          fmt::format("{}: the surface is open ({} boundary loop{}); {} {} builds it", name, loops, plural(loops),
                      request.names(Parameter::Holes),
                      request.structure == geometry::StructureKind::Weave ? "fill or patch" : "keep, fill or patch"));
    }
    if (request.holes == HolesMode::Fill || request.holes == HolesMode::Patch) {
      request.holes == HolesMode::Fill ? geometry::fillHoles(mesh) : geometry::patchHoles(mesh);
      analysis = geometry::analyzeMesh(mesh);
      try {
        geometry::requireUsable(analysis);
      } catch (const geometry::InvalidMeshError& error) {
        throw core::UserError(
            fmt::format("{}: with its {} hole{} filled: {}", name, loops, plural(loops), error.what()));
      }
      context.report({"import", request.holes == HolesMode::Fill ? "holes filled" : "holes patched",
                      static_cast<size_t>(loops), 0});
    }
  }
  // After the holes are filled, so that their caps are among the faces counted.
  std::optional<PanelCount> panelCount;
  if (request.panels) panelCount = remeshedMesh(request, mesh, analysis, context);
  // The mesh as built (after --holes fill): one panel per face.
  const geometry::MeshTopology& topology = analysis.topology;
  counts = {topology.vertices, topology.edges, topology.faces, topology.genus, std::move(repairs), panelCount, start};
  double scale = 0;
  try {
    scale = geometry::constructionScale(mesh, request.size, request.scale, request.names);
  } catch (const std::invalid_argument& error) {
    throw core::UserError(fmt::format("{}: {}", name, error.what()));
  }
  if (!(scale > 0) || !std::isfinite(scale)) {
    throw core::UserError(request.names(Parameter::Scale) + ": expected a positive number");
  }
  for (geometry::Point3& p : mesh.positions) p *= scale;
  return std::move(imported.mesh);
}

}  // namespace making
}  // namespace rotafab::jobs
