#include "jobs/MakeSteps.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "core/UserError.h"
#include "geometry/BandStructure.h"
#include "geometry/ConstructionScale.h"
#include "geometry/EdgeProjection.h"
#include "geometry/FastenerHoles.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshMending.h"
#include "geometry/MeshRepair.h"
#include "geometry/WeaveStructure.h"

namespace rotafab::jobs::making {
namespace {

using geometry::Parameter;

// The advice for bands without room for a hole: the fastener, or the size
// (or the scale, if that is what was given), that gives every band room;
// every length of the structure scales with the mesh.
std::string roomAdvice(const MakeRequest& request, const geometry::PolygonMesh& mesh, double fastener,
                       double scaleNeeded, std::string_view places = "band", bool estimate = false) {
  const auto& names = request.names;
  const core::LengthUnit unit = request.shownIn;
  if (!std::isfinite(scaleNeeded)) {
    return fmt::format("use a smaller {} or a larger {}", names(Parameter::Fastener), names(Parameter::Size));
  }
  // --size is the structure's size, which scales as the mesh does.
  const double size = request.size ? *request.size : geometry::boundingBoxSize(mesh).maxCoeff();
  const std::string larger = request.scale
                                 ? fmt::format("{} {:.4g}", names(Parameter::Scale), *request.scale * scaleNeeded)
                                 : fmt::format("{} {}", names(Parameter::Size), unit.value(size * scaleNeeded, 0, 1));
  const double smaller = std::floor(fastener / scaleNeeded * 1000) / 1000;
  const char* verb = estimate ? "may" : "would";
  return smaller > 0 ? fmt::format("{} {} or smaller, or {} or larger, {} give every {} room",
                                   names(Parameter::Fastener), unit.value(smaller, 3, -1), larger, verb, places)
                     : fmt::format("{} or larger {} give every {} room", larger, verb, places);
}

// The default size grows by at most this much (10%) to give every band its
// fastener; past that, the narrow places are mended where they are.
constexpr double kMostGrowth = 1.10;
// Rounds of mends (each mends each band without room once), at most, and
// rounds in a row that leave no fewer bands without room before make stops.
constexpr int kMendRounds = 60;
constexpr int kStalledRounds = 5;
// Mends are made only where at most this share of the bands have no room.
constexpr double kMostMendedShare = 0.4;
// --size is kept within this share.
constexpr double kSizeTolerance = 0.005;
bool withinSizeTolerance(double side, double size) { return std::abs(side / size - 1) <= kSizeTolerance; }

// What make builds of the mesh: a band decomposition (ch. V) or a
// plain-woven structure (ch. IV), with the options asked; the same sizing,
// mends and refusals serve both. A band's room is its fastener's, a
// crossing's its two holes'.
class StructureBuilder {
 public:
  StructureBuilder(const MakeRequest& request, std::optional<int> start) : kind_(request.structure) {
    const double fastener = request.fastener.value_or(request.material.fastenerDiameter);
    geometry::ParameterNames names = request.names;
    names.unit = request.shownIn;
    band_.tension = request.tension;
    band_.samples = request.samples;
    band_.fastener = fastener;
    band_.start = start;
    band_.up = request.up;
    band_.scoreFolds = request.scoreFolds;
    band_.names = names;
    weave_.cycles = request.cycles;
    // A width asked for is kept (and ribbons that meet at it are warned of);
    // the default is the widest, narrowed where ribbons would meet.
    weave_.shape.width = request.width.value_or(weave_.shape.width);
    weave_.narrowWhereRibbonsMeet = !request.width;
    weave_.shape.curve = request.curve;
    weave_.shape.offset = request.offset.value_or(std::max(request.material.thickness / 2, kLeastOffset));
    weave_.shape.samples = request.samples;
    weave_.fastener = fastener;
    weave_.up = request.up;
    weave_.names = names;
  }

  [[nodiscard]] bool woven() const { return kind_ == geometry::StructureKind::Weave; }
  [[nodiscard]] const char* place() const { return roomPlace(kind_); }
  [[nodiscard]] double fastener() const { return woven() ? weave_.fastener : band_.fastener; }
  void setFastener(double fastener) { (woven() ? weave_.fastener : band_.fastener) = fastener; }
  // Places without room glued, not refused.
  void setGlue(bool glue) { (woven() ? weave_.glueCrossingsWithoutRoom : band_.glueBandsWithoutRoom) = glue; }

  [[nodiscard]] geometry::Structure build(const geometry::PolygonMesh& mesh, const core::WorkContext& context) const {
    return woven() ? geometry::buildWeaveStructure(mesh, weave_, context)
                   : geometry::buildBandStructure(mesh, band_, context);
  }
  // Grown until every place has room (growUntilRoom, Structure.h).
  [[nodiscard]] geometry::GrownStructure buildWithRoom(geometry::PolygonMesh& mesh,
                                                       const core::WorkContext& context) const {
    return woven() ? geometry::buildWeaveStructureWithRoom(mesh, weave_, context)
                   : geometry::buildBandStructureWithRoom(mesh, band_, context);
  }

 private:
  geometry::StructureKind kind_;
  geometry::BandOptions band_;
  geometry::WeaveOptions weave_;
};

// --size is the structure's largest side as built (docs/CONTRACT.md,
// "Units and scale"), not the mesh's: a band decomposition is smaller than
// its mesh (its vertex bands are cut back at the corners), a weave's
// ribbons stand off the surface by the offset and round its corners. The
// mesh, scaled to the size, is measured on a first build (glued, so that
// no place's room stops it) and scaled by the size over the side as
// built. (The band's ratio does not depend on the scale; the weave's
// depends a little, as its offset and the holes' clearance do not grow
// with it: MendingBuild resizes it again until within kSizeTolerance.)
// `mesh` comes at the size asked (constructionScale).
void scaleToBuiltSize(geometry::PolygonMesh& mesh, double size, StructureBuilder builder,
                      const core::WorkContext& context) {
  builder.setGlue(true);
  const double side = builtSize(builder.build(mesh, context)).maxCoeff();
  if (side > 0) {
    for (geometry::Point3& p : mesh.positions) p *= size / side;
  }
}

// Mends the design at each of `places` (the edges of bands or crossings
// without room, or of panels that fold; MeshMending.h: `merges`, faces may
// be merged where no edge collapses; `flipsFirst`, a flip is tried before a
// collapse), if that keeps the mesh usable and its topology; adds what it
// did to `mends`. Returns whether it did anything.
bool mendedWhereNarrow(geometry::PolygonMesh& mesh, const std::vector<std::array<int, 2>>& places, bool merges,
                       bool flipsFirst, geometry::Mends& mends) {
  if (places.empty()) return false;
  geometry::PolygonMesh before = mesh;
  const geometry::Mends made = geometry::mendNarrowPlaces(mesh, places, merges, flipsFirst);
  if (made.count() == 0) return false;
  const geometry::MeshAnalysis was = geometry::analyzeMesh(before), is = geometry::analyzeMesh(mesh);
  if (!is.usable() || is.topology.genus != was.topology.genus || is.topology.components != was.topology.components ||
      is.topology.boundaryLoops != was.topology.boundaryLoops) {
    mesh = std::move(before);
    return false;
  }
  mends.add(made);
  return true;
}

// The mends, among the repairs of the mesh as built, said, and its counts as built.
void recordMends(const geometry::Mends& mends, geometry::PolygonMesh& mesh, BuiltMesh& built, const std::string& name,
                 core::LengthUnit unit, const core::WorkContext& context) {
  for (const geometry::MeshRepair* made : mends.kinds()) {
    if (made->count == 0) continue;
    context.note(fmt::format("{}: repaired: {}", name, made->line(unit)));
    built.repairs.push_back(*made);
  }
  const geometry::MeshTopology topology = geometry::analyzeMesh(mesh).topology;
  built.vertices = topology.vertices;
  built.edges = topology.edges;
  built.faces = topology.faces;
}

// The edges between two faces, about (a boundary edge counts half).
double innerEdges(const geometry::PolygonMesh& mesh) {
  double sides = 0;
  for (const auto& face : mesh.faces) sides += static_cast<double>(face.size());
  return sides / 2;
}

// What make says when bands (or crossings) have no room and no mend gives
// it: the size, and the fastener at this size, at which every one of `mesh` (as drawn,
// before any mend) has room for its holes and its number, each found by
// building it; where that size's panels miss the bed, the fastener alone.
// (A smaller fastener is what a larger size is for the holes, every length
// scaling with the structure, but not for the numbers, which keep their
// smallest height: so it is built too.) `labels`: the bands lack room for
// their numbers, which glue does not give.
struct Advice {
  std::string text;
  bool tried = false;  // built, not estimated
};
Advice triedAdvice(const MakeRequest& request, const geometry::PolygonMesh& mesh, const StructureBuilder& builder,
                   bool labels, const core::WorkContext& context) {
  const auto& names = request.names;
  const auto buildsWith = [&](double fastener) {
    if (!(fastener > 0)) return false;
    StructureBuilder smaller = builder;
    smaller.setFastener(fastener);
    try {
      (void)smaller.build(mesh, context);
      return true;
    } catch (const std::invalid_argument&) {
      return false;  // (no room, or a panel that folds over itself: not a way out either way)
    }
  };
  const std::string glue = labels ? std::string() : fmt::format("; {} glues them", names(Parameter::GlueNarrow));
  const std::string place = builder.place();
  geometry::PolygonMesh larger = mesh;
  try {
    const geometry::GrownStructure grown = builder.buildWithRoom(larger, context);
    const double smaller = std::floor(builder.fastener() / grown.grown * 1000) / 1000;
    const double side = std::ceil(builtSize(grown.structure).maxCoeff());
    const core::LengthUnit unit = request.shownIn;
    const std::string size = fmt::format("{} {}", names(Parameter::Size), unit.value(side, 0, 1));
    const double kerf = request.kerf.value_or(request.material.kerf);
    const bool fastenerBuilds = buildsWith(smaller);
    if (roomOnTheBed(structureParts(grown.structure), request.machine, kerf) < 1) {
      if (fastenerBuilds) {
        return {fmt::format("{} {} or smaller builds it at this size (tried; at {} with this "
                            "fastener a panel is larger than the bed){}",
                            names(Parameter::Fastener), unit.value(smaller, 3, -1), unit(side, 0), glue),
                true};
      }
      return {fmt::format("at {} every {} has room, but a panel is larger than the bed{}", unit(side, 0), place, glue)};
    }
    return {fastenerBuilds ? fmt::format("{} or larger builds it as drawn (tried), or {} {} at this size{}", size,
                                         names(Parameter::Fastener), unit.value(smaller, 3, -1), glue)
                           : fmt::format("{} or larger builds it as drawn (tried){}", size, glue),
            true};
  } catch (const geometry::NoRoomForHoleError& error) {
    if (error.labels) return {"at no larger size tried did every number have room"};
    return {roomAdvice(request, mesh, builder.fastener(), error.scaleNeeded, place, true)};
  } catch (const std::invalid_argument&) {
    return {};  // (larger, a panel folds over itself: make tries a panel count instead)
  }
}

// Whether `face` of `mesh` closes a hole (--holes fill's or patch's).
bool closesAHole(const geometry::PolygonMesh& mesh, int face) {
  return face >= 0 && static_cast<size_t>(face) < mesh.sourceFace.size() &&
         mesh.sourceFace[static_cast<size_t>(face)] == -1;
}

// The structure (band or weave) at the size asked or the default, mended
// where its bands or crossings have no room, or its woven panels fold
// (builtStructure(), MakeSteps.h).
class MendingBuild {
 public:
  MendingBuild(const MakeRequest& request, geometry::PolygonMesh& mesh, BuiltMesh& built, Sizing& sizing,
               const core::WorkContext& context)
      : request_(request),
        mesh_(mesh),
        built_(built),
        sizing_(sizing),
        context_(context),
        name_(request.mesh.string()),
        builder_(request, built.start) {}

  geometry::Structure build() {
    if (request_.size) {
      try {
        scaleToBuiltSize(mesh_, *request_.size, builder_, context_);
      } catch (const geometry::UnfoldOverlapError&) {
        // (A weave's panels folding, or two faces folded flat, mended
        // below: the first build that unfolds is resized to the size asked,
        // and a refusal's way out is measured on the mesh at that size,
        // not the structure's, a few percent apart.)
        if (!builder_.woven()) throw;
      } catch (const geometry::FoldedEdgeError&) {
      }
    }
    asDrawn_ = mesh_;
    return mendedBuild();
  }

 private:
  // The fewest bands without room (or panels folding) a round has left, and the rounds since.
  struct Progress {
    int fewest = std::numeric_limits<int>::max(), stalled = 0;
  };

  // Built, mended round after round where places have no room or panels
  // fold; refused (or glued, as asked) where no mend helps.
  geometry::Structure mendedBuild() {
    for (int round = 0;; ++round) {
      try {
        geometry::Structure structure = builder_.build(mesh_, context_);
        if (resizedToTheSizeAsked(structure)) continue;
        return finished(std::move(structure));
      } catch (const geometry::NoRoomForHoleError& error) {
        // The default size grows by at most kMostGrowth, where that alone gives every place room.
        const bool scaleChosen = !request_.size && !request_.scale;
        if (scaleChosen && round == 0 && !error.estimate && error.scaleNeeded <= kMostGrowth) {
          for (geometry::Point3& p : mesh_.positions) p *= error.scaleNeeded;
          sizing_.grown = error.scaleNeeded;
          continue;
        }
        if (mended(error)) continue;
        return withoutRoom(error);
      } catch (const geometry::FoldedEdgeError& error) {
        // (Two faces folded flat onto each other where a remesh or a mend
        // left them, not a hole's cap: foldedEdgeRefusal() says why that is refused.)
        if (!closesAHole(mesh_, error.leftFace) && !closesAHole(mesh_, error.rightFace) &&
            foldsMended({error.ends}, 1, foldedEdgesProgress_)) {
          continue;
        }
        if (unmended_) {
          if (retriedWithoutMerges()) continue;
          return withoutRoom(*lastError_);
        }
        if (mendedTheOtherWay()) return mendedBuild();
        throw;
      } catch (const geometry::UnfoldOverlapError& error) {
        // (A weave's panels: the band's carry no places, and its mends are those of the bands without room.)
        if (foldsMended(error.places, error.panels, foldsProgress_)) continue;
        if (unmended_) {
          if (retriedWithoutMerges()) continue;
          return withoutRoom(*lastError_);
        }
        if (mendedTheOtherWay()) return mendedBuild();
        if (mends_.count() == 0) throw;
        throw geometry::UnfoldOverlapError(fmt::format("after {}, {}", mendedCount(), error.what()));
      } catch (const std::invalid_argument&) {
        if (!unmended_) throw;
        if (retriedWithoutMerges()) continue;
        return withoutRoom(*lastError_);
      } catch (const geometry::InvalidMeshError&) {
        // (A merged face split again along a diagonal an edge has already.)
        if (!unmended_) throw;
        if (retriedWithoutMerges()) continue;
        return withoutRoom(*lastError_);
      }
    }
  }

  // A weave whose mends, a collapse first, left places without room or
  // panels folding: mended again from the design as drawn, a flip first
  // (mendNarrowPlaces()), which moves no vertex and widens an edge's
  // region where a collapse moved the thin place on. (Each way clears
  // meshes the other does not: CGAL's dino and elk one way, its cylinder
  // the other, docs/PERFORMANCE.md.) Says whether it starts again.
  bool mendedTheOtherWay() {
    if (flipsFirst_ || !builder_.woven() || rounds_ == 0) return false;
    flipsFirst_ = true;
    mesh_ = asDrawn_;
    sizing_.grown = 1;
    mends_ = {};
    unmended_.reset();
    lastError_.reset();
    mendsStopped_ = false;
    merges_ = true;
    resizes_ = 0;
    holesProgress_ = labelsProgress_ = foldsProgress_ = foldedEdgesProgress_ = {};
    rounds_ = 0;
    context_.report({"geometry", fmt::format("mending the {}s again, a flip first", builder_.place()), 0, 0});
    return true;
  }

  // What the mesh was before the last mend, and why it was mended.
  struct Unmended {
    geometry::PolygonMesh mesh;
    geometry::Mends mends;
    geometry::NoRoomForHoleError error;
  };

  // The last mend made a design that cannot be built (two faces merged
  // into one too far from planar): undone, and mended again with collapses
  // alone; after those, no more mends. Says whether it mended again.
  bool retriedWithoutMerges() {
    mesh_ = std::move(unmended_->mesh);
    mends_ = unmended_->mends;
    lastError_ = unmended_->error;
    unmended_.reset();
    if (merges_) {
      merges_ = false;
      if (mended(*lastError_)) return true;
    }
    mendsStopped_ = true;
    return false;
  }

  bool mended(const geometry::NoRoomForHoleError& error) {
    if (request_.keepFaces || mendsStopped_ || ++rounds_ > kMendRounds) return false;
    // Where most bands have no room, the fastener is too large for the
    // design: mending them all would make another shape.
    const bool counted = !error.estimate || error.labels;
    if (counted && error.bands > kMostMendedShare * innerEdges(mesh_)) return false;
    // Rounds go on while they leave fewer bands without room (a tab's
    // error, which names one band and stops the build there, does not
    // count). Bands whose numbers have no room are found only once every
    // hole has room, and their mends may leave new bands without room for a
    // hole: each kind is counted apart, and the holes afresh after each
    // round of numbers.
    if (counted) {
      Progress& progress = error.labels ? labelsProgress_ : holesProgress_;
      if (error.labels) holesProgress_ = {};
      if (error.bands < progress.fewest) {
        progress = {error.bands, 0};
      } else if (++progress.stalled >= kStalledRounds) {
        return false;
      }
    }
    unmended_ = Unmended{mesh_, mends_, error};
    if (!mendedWhereNarrow(mesh_, error.places, merges_, flipsFirst_, mends_)) return false;
    context_.report(
        {"geometry", fmt::format("narrow {}s mended", builder_.place()), static_cast<size_t>(mends_.count()), 0});
    return true;
  }

  // Panels of a weave that fold over themselves at their own crossing,
  // where a sliver beside its edge makes the edge's region thin and the
  // ribbon's rows there nearly along it: the sliver collapsed or flipped
  // as a narrow place is, round after round while fewer panels fold.
  // (`progress`: the panels' own, or the edges folded flat's, which stop
  // the build at the first: at most kStalledRounds of those in a row.)
  bool foldsMended(const std::vector<std::array<int, 2>>& places, int panels, Progress& progress) {
    if (places.empty() || request_.keepFaces || mendsStopped_ || ++rounds_ > kMendRounds) return false;
    if (panels < progress.fewest) {
      progress = {panels, 0};
    } else if (++progress.stalled >= kStalledRounds) {
      return false;
    }
    if (!mendedWhereNarrow(mesh_, places, false, flipsFirst_, mends_)) return false;
    context_.report({"geometry", "folding panels mended", static_cast<size_t>(mends_.count()), 0});
    return true;
  }

  std::string mendedCount() const {
    return fmt::format("{} narrow place{} mended", mends_.count(), mends_.count() == 1 ? " was" : "s were");
  }

  // --size kept within kSizeTolerance: a mend moves a few vertices, and
  // may move the box's side a little; a weave's side as built depends a
  // little on its scale. Resized at most kMostResizes times, then refused
  // rather than built at another size (of no use to the builders; not met
  // on any of CGAL's meshes woven at --panels 400 --size 36in,
  // docs/PERFORMANCE.md).
  bool resizedToTheSizeAsked(const geometry::Structure& structure) {
    constexpr int kMostResizes = 3;
    if (!request_.size) return false;
    const double size = *request_.size;
    const double side = builtSize(structure).maxCoeff();
    if (!(side > 0) || withinSizeTolerance(side, size)) return false;
    if (resizes_ == kMostResizes) {
      const core::LengthUnit unit = request_.shownIn;
      throw core::UserError(
          fmt::format("{}: built, its largest side came out {}, not the {} asked, after {} "
                      "resizes; {} sets the size of the mesh itself",
                      name_, unit(side, 2), unit(size, 2), kMostResizes, request_.names(Parameter::Scale)));
    }
    for (geometry::Point3& p : mesh_.positions) p *= size / side;
    ++resizes_;
    return true;
  }

  geometry::Structure finished(geometry::Structure structure) {
    if (flipsFirst_) {
      context_.note(
          fmt::format("{}: mended a second time from the mesh as drawn, a flip tried before a collapse "
                      "(with a collapse first, {}s were left without room or panels folding)",
                      name_, builder_.place()));
    }
    if (mends_.count() > 0) recordMends(mends_, mesh_, built_, name_, request_.shownIn, context_);
    if (sizing_.grown > 1) {
      const core::LengthUnit unit = request_.shownIn;
      context_.note(fmt::format(
          "{}: scaled to a mean edge of {}, not {} ({:.0f}% larger, {} at its largest side): at "
          "that size{} every {} has room for its {} fastener{}; {} or {} sets the size",
          name_, unit(geometry::kMeanEdgeInches * sizing_.grown, 2), unit(geometry::kMeanEdgeInches, 2),
          100 * (sizing_.grown - 1), unit(builtSize(structure).maxCoeff(), 1),
          // (A weave's scale asked is an estimate, which mends may have made up.)
          mends_.count() > 0 ? ", and its narrow places mended," : "", builder_.place(), unit(builder_.fastener(), 3),
          builder_.woven() ? " holes" : "", request_.names(Parameter::Size), request_.names(Parameter::Scale)));
    }
    return structure;
  }

  // Places without room that no mend gives room: glued if asked, else the job refused with a way out.
  // (`error` a copy: the other way's start resets lastError_.)
  geometry::Structure withoutRoom(geometry::NoRoomForHoleError error) {
    if (mendedTheOtherWay()) return mendedBuild();
    const auto& names = request_.names;
    if (request_.glueNarrow) {
      builder_.setGlue(true);
      geometry::Structure built = builder_.build(mesh_, context_);
      while (resizedToTheSizeAsked(built)) built = builder_.build(mesh_, context_);
      geometry::Structure glued = finished(std::move(built));
      const size_t n = glued.glued.size();
      // (Where only labels had no room, the build's own warning names those left off.)
      if (n > 0)
        glued.warnings.push_back(fmt::format("{} {}{} without room for a {} fastener {} glued, as {} asks", n,
                                             builder_.place(), plural(static_cast<int>(n)),
                                             request_.shownIn(builder_.fastener(), 3), n == 1 ? "is" : "are",
                                             names(Parameter::GlueNarrow)));
      return glued;
    }
    const std::string after = mends_.count() > 0   ? " after " + mendedCount()
                              : request_.keepFaces ? fmt::format(" ({} keeps every face)", names(Parameter::KeepFaces))
                                                   : std::string();
    // (make's own tries of a way out need only know that this one failed.)
    const Advice advice =
        request_.adviseWayOut ? triedAdvice(request_, asDrawn_, builder_, error.labels, context_) : Advice{};
    throw StructureRefused(name_, error.bandsWithoutRoom + after, advice.text, advice.tried);
  }

  const MakeRequest& request_;
  geometry::PolygonMesh& mesh_;
  geometry::PolygonMesh asDrawn_;  // at the size asked, before any mend
  BuiltMesh& built_;
  Sizing& sizing_;
  const core::WorkContext& context_;
  const std::string name_;
  StructureBuilder builder_;
  geometry::Mends mends_;
  std::optional<Unmended> unmended_;
  std::optional<geometry::NoRoomForHoleError> lastError_;
  bool mendsStopped_ = false, merges_ = true, flipsFirst_ = false;
  int resizes_ = 0;
  Progress holesProgress_, labelsProgress_, foldsProgress_, foldedEdgesProgress_;
  int rounds_ = 0;
};

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

namespace {

// A weave refused at an edge whose two faces fold back onto each other:
// where one of them closes a hole, what closes it, and that an open
// surface flat there has no inside to weave around.
std::string foldedEdgeRefusal(const MakeRequest& request, const geometry::PolygonMesh& mesh,
                              const geometry::FoldedEdgeError& error) {
  const std::string name = request.mesh.string();
  const int closing = (closesAHole(mesh, error.leftFace) ? 1 : 0) + (closesAHole(mesh, error.rightFace) ? 1 : 0);
  if (closing == 0) return fmt::format("{}: {}", name, error.what());
  if (closing == 2) {
    return fmt::format(
        "{}: {}: both close a hole, with triangles folded onto each other; an open "
        "surface that is flat about its hole has no inside to weave around",
        name, error.what());
  }
  return fmt::format(
      "{}: {}: one of them closes a hole, {}; an open surface that is flat about its hole has no inside to weave "
      "around with either",
      name, error.what(),
      request.holes == HolesMode::Fill
          ? fmt::format("with one face ({} patch closes it with triangles like the mesh's own, which bend with a "
                        "bent hole)",
                        request.names(Parameter::Holes))
          : std::string("with triangles that lie back against the surface beside it"));
}

}  // namespace

geometry::Structure builtStructure(const MakeRequest& request, geometry::PolygonMesh& mesh, BuiltMesh& built,
                                   Sizing& sizing, const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  const bool woven = request.structure == geometry::StructureKind::Weave;
  try {
    return MendingBuild(request, mesh, built, sizing, context).build();
  } catch (const geometry::NoRoomForHoleError& error) {
    // (Not thrown once the mends are done, which refuse with a way out: the
    // measuring build of --size glues, but a band's tab may still throw its
    // estimate. A weave's scale asked is always one.)
    const double fastener = request.fastener.value_or(request.material.fastenerDiameter);
    throw StructureRefused(
        name, error.bandsWithoutRoom,
        roomAdvice(request, mesh, fastener, error.scaleNeeded, roomPlace(request.structure), woven || error.estimate),
        false);
  } catch (const geometry::UnfoldOverlapError& error) {
    // (Panels that overlap or fold over themselves: fewer, evener faces or a size may build it.)
    throw StructureRefused(name, error.what(), "", false);
  } catch (const geometry::FoldedEdgeError& error) {
    throw core::UserError(foldedEdgeRefusal(request, mesh, error));
  } catch (const std::invalid_argument& error) {
    throw StructureRefused(name, error.what() + (woven ? oneFaceCapAdvice(request, mesh) : std::string()), "", false,
                           false);
  } catch (const geometry::InvalidMeshError& error) {
    throw StructureRefused(name, error.what(), "", false, false);
  }
}

}  // namespace rotafab::jobs::making
