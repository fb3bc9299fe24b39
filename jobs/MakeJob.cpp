#include "jobs/MakeJob.h"

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
#include "geometry/Simplification.h"
#include "geometry/WeaveStructure.h"
#include "geometry/io/MeshImport.h"
#include "jobs/OutputFolder.h"
#include "toolpath/AtomicFile.h"
#include "toolpath/Toolpath.h"

namespace rotafab::jobs {
namespace {

using geometry::Parameter;

// Seconds since the last call.
class Lap {
 public:
  double operator()() {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return elapsed;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

const char* plural(int n) { return n == 1 ? "" : "s"; }

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

namespace {

// --panels N: the mesh simplified to about N faces (after the merge of
// coplanar faces, so that flat regions are taken first and nothing merges
// the count down after), its topology checked to be the same.
geometry::Simplification simplifiedMesh(const MakeRequest& request, geometry::PolygonMesh& mesh,
                                        geometry::MeshAnalysis& analysis, const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  const geometry::MeshTopology before = analysis.topology;
  geometry::Simplification simplified;
  try {
    simplified = geometry::simplifyMesh(mesh, *request.panels, context);
  } catch (const geometry::InvalidMeshError& error) {
    throw core::UserError(fmt::format("{}: {}", name, error.what()));
  } catch (const std::invalid_argument& error) {
    throw core::UserError(
        fmt::format("{}: {} {}: {}", name, request.names(Parameter::Panels), *request.panels, error.what()));
  }
  if (!simplified.simplified()) {
    context.note(fmt::format("{}: {} faces, no more than the {} asked: not simplified", name, simplified.facesBefore,
                             simplified.asked));
    return simplified;
  }
  analysis = geometry::analyzeMesh(mesh);
  const geometry::MeshTopology& after = analysis.topology;
  if (after.genus != before.genus || after.components != before.components ||
      after.boundaryLoops != before.boundaryLoops || !analysis.problems.empty()) {
    // The decimater refuses every collapse that changes the topology; this is the proof.
    throw core::UserError(fmt::format("{}: simplified to {} faces it would not keep its topology; build it without {}",
                                      name, simplified.facesAfter, request.names(Parameter::Panels)));
  }
  context.note(fmt::format("{}: simplified from {} faces{} to {} ({} asked), keeping its genus and boundary", name,
                           simplified.facesBefore, simplified.triangulated ? " (polygons split into triangles)" : "",
                           simplified.facesAfter, simplified.asked));
  return simplified;
}

// The mesh as read, checked, its holes filled if asked, at construction size.
geometry::PolygonMesh importedMesh(const MakeRequest& request, BuiltMesh& counts, const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  context.report({"import", "", 0, 0});
  geometry::ImportedMesh imported = geometry::importMesh(request.mesh, &context.cancellation());
  for (const auto& warning : imported.warnings) context.warn(fmt::format("{}: {}", name, warning));
  geometry::PolygonMesh& mesh = imported.mesh;
  std::vector<geometry::MeshRepair> repairs;
  if (request.repair) {
    repairs = geometry::repairMesh(mesh);
    for (const auto& repair : repairs) context.note(fmt::format("{}: repaired: {}", name, repair.line()));
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
  std::optional<geometry::Simplification> simplified;
  if (request.panels) {
    simplified = simplifiedMesh(request, mesh, analysis, context);
  }
  // The mesh as built (after --holes fill): one panel per face.
  const geometry::MeshTopology& topology = analysis.topology;
  counts = {topology.vertices, topology.edges, topology.faces, topology.genus, std::move(repairs), simplified, start};
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

// The sides of the box of the structure as built (its panels in 3D).
geometry::Point3 builtSize(const geometry::Structure& structure) {
  return geometry::boundingBoxSize(geometry::surfaceMesh(structure));
}

// The advice for bands without room for a hole: the fastener, or the size
// (or the scale, if that is what was given), that gives every band room;
// every length of the structure scales with the mesh.
std::string roomAdvice(const MakeRequest& request, const geometry::PolygonMesh& mesh, double fastener,
                       double scaleNeeded, std::string_view places = "band", bool estimate = false) {
  const auto& names = request.names;
  if (!std::isfinite(scaleNeeded)) {
    return fmt::format("use a smaller {} or a larger {}", names(Parameter::Fastener), names(Parameter::Size));
  }
  // --size is the structure's size, which scales as the mesh does.
  const double size = request.size ? *request.size : geometry::boundingBoxSize(mesh).maxCoeff();
  const std::string larger = request.scale
                                 ? fmt::format("{} {:.4g}", names(Parameter::Scale), *request.scale * scaleNeeded)
                                 : fmt::format("{} {:.0f}in", names(Parameter::Size), std::ceil(size * scaleNeeded));
  const double smaller = std::floor(fastener / scaleNeeded * 1000) / 1000;
  const char* verb = estimate ? "may" : "would";
  return smaller > 0 ? fmt::format("{} {:.3f}in or smaller, or {} or larger, {} give every {} room",
                                   names(Parameter::Fastener), smaller, larger, verb, places)
                     : fmt::format("{} or larger {} give every {} room", larger, verb, places);
}

// How the structure's size was chosen, when make chose it.
struct Sizing {
  double grown = 1;         // times the default size (1: as it was)
  bool bedLimited = false;  // limited by the bed or by the narrowest bands, which are glued
};

// A plain-woven structure (dissertation ch. IV) of the mesh as built. The
// ribbons follow the surface within the offset, so --size scales the mesh;
// with no size or scale given it grows until every crossing has room for
// its two holes.
// What to add to a refusal when the mesh's holes were capped with one face
// each: such a cap across a wide or bent hole folds back over its
// neighbours or makes panels as wide as the hole, and a patch avoids it.
std::string oneFaceCapAdvice(const MakeRequest& request, const geometry::PolygonMesh& mesh) {
  const bool capped = request.holes == HolesMode::Fill &&
                      std::find(mesh.sourceFace.begin(), mesh.sourceFace.end(), -1) != mesh.sourceFace.end();
  return capped ? fmt::format(
                      " (its holes are capped with one face each: {} patch closes them with triangles like "
                      "the mesh's own)",
                      request.names(Parameter::Holes))
                : "";
}

geometry::Structure builtWeave(const MakeRequest& request, geometry::PolygonMesh& mesh, Sizing& sizing,
                               const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  geometry::WeaveOptions weave;
  weave.cycles = request.cycles;
  // A width asked for is kept (and ribbons that meet at it are warned of);
  // the default is the widest, narrowed where ribbons would meet.
  weave.shape.width = request.width.value_or(weave.shape.width);
  weave.narrowWhereRibbonsMeet = !request.width;
  weave.shape.curve = request.curve;
  weave.shape.offset = request.offset.value_or(std::max(request.material.thickness / 2, kLeastOffset));
  weave.shape.samples = request.samples;
  weave.fastener = request.fastener.value_or(request.material.fastenerDiameter);
  weave.up = request.up;
  weave.names = request.names;
  try {
    if (request.size) {
      const double side = geometry::boundingBoxSize(mesh).maxCoeff();
      if (side > 0) {
        for (geometry::Point3& p : mesh.positions) p *= *request.size / side;
      }
    }
    if (request.size || request.scale) return geometry::buildWeaveStructure(mesh, weave, context);
    geometry::GrownStructure built = geometry::buildWeaveStructureWithRoom(mesh, weave, context);
    sizing.grown = built.grown;
    const double kerf = request.kerf.value_or(request.material.kerf);
    if (built.grown > 1 && roomOnTheBed(structureParts(built.structure), request.machine, kerf) < 1) {
      // The size at which every crossing has room makes a panel larger than
      // the bed (a mesh whose faces differ much in size): as for a band
      // decomposition, the largest size that fits the bed, no smaller than
      // the default, and the crossings without room there glued.
      weave.glueCrossingsWithoutRoom = true;
      constexpr int kShrinkAttempts = 3;
      const double grownAtFirst = built.grown;
      geometry::Structure glued = std::move(built.structure);
      double room = roomOnTheBed(structureParts(glued), request.machine, kerf);
      for (int attempt = 1; attempt <= kShrinkAttempts && room < 1; ++attempt) {
        // (1% to spare: a label's size does not grow with the rest; never below the default size)
        const double shrink = std::max(0.99 * room, 1 / sizing.grown);
        if (!(shrink < 1)) break;
        for (geometry::Point3& p : mesh.positions) p *= shrink;
        sizing.grown *= shrink;
        context.report({"geometry", "smaller, for the bed", static_cast<size_t>(attempt), 0});
        glued = geometry::buildWeaveStructure(mesh, weave, context);
        room = roomOnTheBed(structureParts(glued), request.machine, kerf);
      }
      // (Still over the bed: the planner's refusal names the panel, with the size advice.)
      if (room < 1) return glued;
      sizing.bedLimited = true;
      context.note(fmt::format(
          "{}: scaled to a mean edge of {:.2f} in, not {:g} in, the largest size that fits the bed, below the {:.2f} "
          "in at which every crossing has room for {:.3f} in fastener holes; {} crossing{} without room {} glued; {} "
          "N, fewer and evener faces, needs less",
          name, geometry::kMeanEdgeInches * sizing.grown, geometry::kMeanEdgeInches,
          geometry::kMeanEdgeInches * grownAtFirst, weave.fastener, glued.glued.size(),
          plural(static_cast<int>(glued.glued.size())), glued.glued.size() == 1 ? "is" : "are",
          request.names(Parameter::Panels)));
      return glued;
    }
    if (built.grown > 1) {
      context.note(fmt::format(
          "{}: scaled to a mean edge of {:.2f} in, not {:g} in, the smallest size at which its crossings have room "
          "for {:.3f} in fastener holes, all but one in a hundred ({} crossing{} had none at the default size); {} or "
          "{} sets the size",
          name, geometry::kMeanEdgeInches * built.grown, geometry::kMeanEdgeInches, weave.fastener,
          built.bandsWithoutRoom, plural(built.bandsWithoutRoom), request.names(Parameter::Size),
          request.names(Parameter::Scale)));
    }
    return std::move(built.structure);
  } catch (const geometry::NoRoomForHoleError& error) {
    // (An estimate: the ribbons' offset does not grow with the mesh.)
    throw core::UserError(fmt::format("{}: {}; {}", name, error.bandsWithoutRoom,
                                      roomAdvice(request, mesh, weave.fastener, error.scaleNeeded, "crossing", true)));
  } catch (const geometry::FoldedEdgeError& error) {
    // Where one of the two faces closes a hole, say what closes it, and
    // that an open surface flat there has no inside to weave around.
    const auto closesAHole = [&](int face) {
      return face >= 0 && static_cast<size_t>(face) < mesh.sourceFace.size() &&
             mesh.sourceFace[static_cast<size_t>(face)] == -1;
    };
    const int closing = (closesAHole(error.leftFace) ? 1 : 0) + (closesAHole(error.rightFace) ? 1 : 0);
    if (closing == 0) throw core::UserError(fmt::format("{}: {}", name, error.what()));
    if (closing == 2) {
      throw core::UserError(
          fmt::format("{}: {}: both close a hole, with triangles folded onto each other; an open "
                      "surface that is flat about its hole has no inside to weave around",
                      name, error.what()));
    }
    throw core::UserError(fmt::format(
        "{}: {}: one of them closes a hole, {}; an open surface that is flat about its hole has no inside to weave "
        "around with either",
        name, error.what(),
        request.holes == HolesMode::Fill
            ? fmt::format("with one face ({} patch closes it with triangles like the mesh's own, which bend with a "
                          "bent hole)",
                          request.names(Parameter::Holes))
            : std::string("with triangles that lie back against the surface beside it")));
  } catch (const std::invalid_argument& error) {
    throw core::UserError(fmt::format("{}: {}{}", name, error.what(), oneFaceCapAdvice(request, mesh)));
  }
}

// `start`: the flood fill's first face in the mesh as built.
geometry::Structure builtStructure(const MakeRequest& request, geometry::PolygonMesh& mesh, std::optional<int> start,
                                   Sizing& sizing, const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  geometry::BandOptions band;
  band.tension = request.tension;
  band.samples = request.samples;
  band.fastener = request.fastener.value_or(request.material.fastenerDiameter);
  band.start = start;
  band.up = request.up;
  band.scoreFolds = request.scoreFolds;
  band.names = request.names;
  // With no size or scale given, the structure grows until every band has room for its fastener.
  const bool scaleChosen = !request.size && !request.scale;
  const double defaultSide = geometry::boundingBoxSize(mesh).maxCoeff();
  const auto grownBy = [&] { return geometry::boundingBoxSize(mesh).maxCoeff() / defaultSide; };
  const double kerf = request.kerf.value_or(request.material.kerf);
  const auto roomOnTheBedFor = [&](const geometry::Structure& structure) {
    return roomOnTheBed(structureParts(structure), request.machine, kerf);
  };
  const auto sized = [&](const std::string& why, const geometry::Structure& structure) {
    return fmt::format(
        "{}: scaled to a mean edge of {:.2f} in, not {:g} in ({:.1f} in at its largest side), {}; {} N, fewer and "
        "evener faces, may need less; {} or {} sets the size",
        name, geometry::kMeanEdgeInches * sizing.grown, geometry::kMeanEdgeInches, builtSize(structure).maxCoeff(), why,
        request.names(Parameter::Panels), request.names(Parameter::Size), request.names(Parameter::Scale));
  };
  try {
    if (request.size) {
      // --size is the structure's largest side (docs/CONTRACT.md,
      // "Units and scale"), and the structure is smaller than the mesh (its
      // vertex bands are cut back at the corners), by a ratio that does not
      // depend on the scale: measured on a first build (glued, so that no
      // band's room stops it), then the mesh scaled by it.
      geometry::BandOptions measuring = band;
      measuring.glueBandsWithoutRoom = true;
      const double side = builtSize(geometry::buildBandStructure(mesh, measuring, context)).maxCoeff();
      if (side > 0) {
        for (geometry::Point3& p : mesh.positions) p *= *request.size / side;
      }
    }
    if (!scaleChosen) return geometry::buildBandStructure(mesh, band, context);
    std::optional<geometry::GrownStructure> built;
    int narrow = 0;
    std::optional<geometry::NoRoomForHoleError> noRoom;
    try {
      built = geometry::buildBandStructureWithRoom(mesh, band, context);
      narrow = built->bandsWithoutRoom;
    } catch (const geometry::NoRoomForHoleError& error) {
      narrow = error.bands;
      noRoom = error;
    }
    sizing.grown = grownBy();
    if (built && (sizing.grown <= 1 || roomOnTheBedFor(built->structure) >= 1)) {
      if (sizing.grown > 1) {
        context.note(sized(fmt::format("the smallest size at which every band has room for its {:.3f} in fastener "
                                       "hole {:g} diameter from every outline ({} band{} had none: narrow faces)",
                                       band.fastener, geometry::kLeastClearance, narrow, narrow == 1 ? "" : "s"),
                           built->structure));
      }
      return std::move(built->structure);
    }
    // The size at which every band has room misses the bed, or growing did
    // not find one: the largest size that fits the bed, no smaller than the
    // default, and the bands still without room glued.
    band.glueBandsWithoutRoom = true;
    // Nor larger than needed: a few slivers may ask for a size many times
    // any other band's. At most the size at which all but one band in a
    // hundred have room (each band without room at the default size said
    // how much larger it needs to be).
    std::vector<double> scales = built ? built->scalesNeeded : noRoom ? noRoom->scales : std::vector<double>{};
    std::sort(scales.begin(), scales.end(), std::greater<>());
    size_t sides = 0;
    for (const auto& face : mesh.faces) sides += face.size();
    const size_t mayGlue = sides / 2 / 100;  // of the edges, about
    if (mayGlue < scales.size() && scales[mayGlue] < grownBy()) {
      const double shrink = std::max(scales[mayGlue], 1.0) / grownBy();
      for (geometry::Point3& p : mesh.positions) p *= shrink;
    }
    geometry::Structure glued;
    constexpr int kShrinkAttempts = 3;
    for (int attempt = 1;; ++attempt) {
      glued = geometry::buildBandStructure(mesh, band, context);
      const double room = roomOnTheBedFor(glued);
      if (room >= 1 || attempt == kShrinkAttempts || grownBy() <= 1) break;
      // (1% to spare: a tab's and a label's sizes do not grow with the rest)
      const double shrink = std::max(0.99 * room, 1 / grownBy());
      for (geometry::Point3& p : mesh.positions) p *= shrink;
      context.report({"geometry", "smaller, for the bed", static_cast<size_t>(attempt), 0});
    }
    // Glue alone is not what a fastener was chosen for: then the size at
    // which the fasteners fit, and the error that it misses the bed.
    if (glued.fasteners == 0) {
      if (noRoom) throw *noRoom;
      sizing.grown = grownBy();
      for (geometry::Point3& p : mesh.positions) p *= built->grown / sizing.grown;
      sizing.grown = grownBy();
      return std::move(built->structure);
    }
    sizing.grown = grownBy();
    sizing.bedLimited = true;
    if (sizing.grown > 1) {
      const size_t n = glued.glued.size();
      context.note(sized(
          fmt::format("at most the largest size that fits the bed and that at which all but 1 in 100 bands have room "
                      "for its {:.3f} in fastener; {} band{} without room {} glued (narrow faces)",
                      band.fastener, n, n == 1 ? "" : "s", n == 1 ? "is" : "are"),
          glued));
    }
    return glued;
  } catch (const geometry::NoRoomForHoleError& error) {
    if (error.estimate) {
      throw core::UserError(
          fmt::format("{}: {}; a larger {} may give it room, or split that face in the mesh, or "
                      "simplify the mesh ({} N)",
                      name, error.bandsWithoutRoom, request.names(Parameter::Size), request.names(Parameter::Panels)));
    }
    throw core::UserError(fmt::format("{}: {}; {}", name, error.bandsWithoutRoom,
                                      roomAdvice(request, mesh, band.fastener, error.scaleNeeded)));
  } catch (const std::invalid_argument& error) {
    throw core::UserError(fmt::format("{}: {}", name, error.what()));
  }
}

// Square inches to square metres: the areal density is in grams per square metre.
constexpr double kSquareMetresPerSquareInch = 0.0254 * 0.0254;

geometry::StabilityOptions stabilityOptions(const MakeRequest& request) {
  geometry::StabilityOptions options;
  options.up = request.up;
  options.gramsPerSquareInch = request.material.arealDensity * kSquareMetresPerSquareInch;
  options.gramsPerFastener = request.material.fastenerMass;
  return options;
}

}  // namespace

std::filesystem::path defaultOutputFolder(const MakeRequest& request) {
  return request.mesh.stem().string() + "-" + std::string(geometry::structureName(request.structure));
}

// The sheets, the fasteners and the cutting time, sheet by sheet, on the
// profile's machine (the toolpath `rotafab run` would send, and its time).
JobCost jobCost(const PlannedJob& job, const MakeRequest& request, const core::WorkContext& context) {
  JobCost cost;
  cost.material = request.material.name;
  cost.sheets = job.sheets.sheets.size();
  cost.sheetWidth = request.machine.bed.width, cost.sheetHeight = request.machine.bed.height;
  cost.fasteners = job.structure.fasteners;
  cost.fastenerDiameter = request.fastener.value_or(request.material.fastenerDiameter);
  cost.motionGiven = request.machine.motion.has_value();
  const MotionLimits limits = profileMotion(request.machine);
  // (Each sheet's stroke order is its own work: shared out among the threads.)
  std::vector<double> seconds(job.sheets.sheets.size(), 0.0);
  std::vector<std::string> refused(seconds.size());
  context.parallelFor(seconds.size(), [&](size_t s) {
    try {
      seconds[s] = planToolpath(job.sheets.sheets[s], request.machine, request.material, limits).seconds;
    } catch (const std::invalid_argument& error) {
      refused[s] = error.what();
    }
  });
  context.check();
  if (const auto why = std::find_if(refused.begin(), refused.end(), [](const auto& r) { return !r.empty(); });
      why != refused.end()) {
    context.warn(fmt::format("{}: no cutting time: {}", request.mesh.string(), *why));
  } else {
    cost.cuttingSeconds = std::move(seconds);
  }
  return cost;
}

PlannedJob planJob(const MakeRequest& request, const core::WorkContext& context) {
  Lap lap;
  const std::string name = request.mesh.string();
  PlannedJob job;
  job.title = fmt::format("{} ({})", request.mesh.stem().string(), geometry::structureName(request.structure));
  geometry::PolygonMesh mesh = importedMesh(request, job.mesh, context);
  job.seconds.import = lap();
  context.check();

  Sizing sizing;
  job.structure = request.structure == geometry::StructureKind::Weave
                      ? builtWeave(request, mesh, sizing, context)
                      : builtStructure(request, mesh, job.mesh.start, sizing, context);
  for (const auto& note : job.structure.notes) context.note(fmt::format("{}: {}", name, note));
  for (const auto& warning : job.structure.warnings) context.warn(fmt::format("{}: {}", name, warning));
  job.stability = geometry::structureStability(job.structure, stabilityOptions(request));
  job.size = builtSize(job.structure);
  job.seconds.geometry = lap();

  PlanOptions plan;
  plan.kerf = request.kerf.value_or(request.material.kerf);
  plan.seconds = request.seconds;
  plan.evaluations = request.evaluations;
  plan.order = request.order;
  plan.window = request.window;
  plan.freeOrderWhenItSavesSheets = request.freeOrderWhenItSavesSheets;
  plan.rows = request.rows;
  plan.title = job.title;
  context.report({"nesting", "", 0, job.structure.panels.size()});
  try {
    // (The parts, copies of the panels' outlines and strokes, only while they are planned.)
    job.sheets = planSheets(structureParts(job.structure), request.machine, plan, context);
  } catch (const std::invalid_argument& error) {
    throw core::UserError(fmt::format(
        "{}: {}{}{}", name, error.what(),
        sizing.grown > 1 && !sizing.bedLimited
            ? fmt::format(" at {:.2f} times the default size, the smallest at which every {} has room for "
                          "its fastener{}; a smaller {}, or fewer and evener faces ({} N), needs less",
                          sizing.grown, request.structure == geometry::StructureKind::Weave ? "crossing" : "band",
                          request.structure == geometry::StructureKind::Weave ? " holes" : "",
                          request.names(Parameter::Fastener), request.names(Parameter::Panels))
            : "",
        oneFaceCapAdvice(request, mesh)));
  }
  job.meshFile = request.mesh;
  job.bed = request.machine.bed;
  job.formats = request.formats.value_or(defaultFormats(request.machine));
  job.seconds.nesting = lap();
  if (job.sheets.windowSheets > 0) {
    context.note(fmt::format(
        "{}: cut in the free order: keeping each part within {} places of the assembly order took {} sheets, the "
        "free order {} (manifest.json's `moved` says how far each part moved; --order window keeps the window)",
        name, request.window, job.sheets.windowSheets, job.sheets.sheets.size()));
  }
  if (!job.sheets.inRowsNote.empty()) context.note(fmt::format("{}: {}", name, job.sheets.inRowsNote));
  job.cost = jobCost(job, request, context);
  job.seconds.estimate = lap();
  return job;
}

void writeJob(PlannedJob& job, const std::filesystem::path& folder, const core::WorkContext& context) {
  Lap lap;
  context.report({"writing", "", 0, job.sheets.sheets.size()});
  OutputFolder output(folder);
  job.files = writeSheets(job.sheets, job.formats, output.staging(), context);
  context.check();
  writeFileAtomically(output.staging() / "structure.obj", [&](std::ostream& stream) {
    geometry::writeStructureObj(
        stream, job.structure,
        fmt::format("rotafab {} structure of {}: {} panels, inches", geometry::structureName(job.structure.kind),
                    job.meshFile.string(), job.structure.panels.size()),
        kSheetDecimals);
  });
  {
    const nlohmann::ordered_json more = {{"size", {job.size.x(), job.size.y(), job.size.z()}},
                                         {"stability", stabilityJson(job.stability)},
                                         {"cost", costJson(job.cost)}};
    ManifestFiles manifest = manifestFiles(job.structure, job.mesh, job.bed, job.sheets, job.files, more, context);
    writeFileAtomically(output.staging() / "manifest.json", manifest.json);
    std::string().swap(manifest.json);
    writeFileAtomically(output.staging() / "manifest.txt", manifest.text);
  }
  context.check();
  // manifest.json last: until it moves in, the folder's manifest is the old job's.
  static const std::regex ours(
      R"((sheet-\d{3,}\.(eps|svg|dxf|preview\.svg))|manifest\.json|manifest\.txt|structure\.obj)");
  output.commit("manifest.json", [](const std::string& name) { return std::regex_match(name, ours); });
  job.folder = output.target();
  job.seconds.writing = lap();
}

nlohmann::ordered_json summaryJson(const PlannedJob& job) {
  const PhaseSeconds& s = job.seconds;
  nlohmann::ordered_json summary = {{"panels", job.structure.panels.size()},
                                    {"sheets", job.sheets.sheets.size()},
                                    {"fasteners", job.structure.fasteners},
                                    {"utilization", job.sheets.utilization},
                                    {"seconds",
                                     {{"import", s.import},
                                      {"geometry", s.geometry},
                                      {"nesting", s.nesting},
                                      {"estimate", s.estimate},
                                      {"writing", s.writing}}}};
  if (job.mesh.simplified) summary["simplified"] = simplifiedJson(*job.mesh.simplified);
  summary["size"] = {job.size.x(), job.size.y(), job.size.z()};
  summary["stability"] = stabilityJson(job.stability);
  summary["cost"] = costJson(job.cost);
  return summary;
}

PlannedJob makeJob(const MakeRequest& request, const std::filesystem::path& folder, const core::WorkContext& context) {
  PlannedJob job = planJob(request, context);
  writeJob(job, folder, context);
  return job;
}

}  // namespace rotafab::jobs
