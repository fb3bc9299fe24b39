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
#include "geometry/Simplification.h"
#include "geometry/WeaveStructure.h"
#include "geometry/io/MeshImport.h"

namespace rotafab::jobs::making {
namespace {

using geometry::Parameter;

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

}  // namespace

geometry::Point3 builtSize(const geometry::Structure& structure) {
  return geometry::boundingBoxSize(geometry::surfaceMesh(structure));
}

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

}  // namespace rotafab::jobs::making
