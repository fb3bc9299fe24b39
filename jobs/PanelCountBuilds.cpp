// make's builds for --panels N (docs/structures.md, "Size"): the mesh
// imported and its structure built, and, where the panels built miss N or
// the build is refused, the mesh remeshed again to other counts of even
// triangles within kPanelCountTolerance of N, each built quietly; only the
// build kept says its notes.

#include "jobs/MakeSteps.h"

#include <fmt/format.h>

#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>
#include <utility>

#include "core/UserError.h"

namespace rotafab::jobs::making {
namespace {

// The mesh imported and its structure built (the import and geometry
// phases); `side`: the mesh's largest side as imported, at the size asked.
// A refusal is builtStructure()'s, its way out not yet tried.
geometry::PolygonMesh importedAndBuilt(const MakeRequest& request, PlannedJob& job, Sizing& sizing, double& side,
                                       const core::WorkContext& context) {
  const auto began = std::chrono::steady_clock::now();
  geometry::PolygonMesh mesh = importedMesh(request, job.mesh, context);
  job.seconds.import += std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  context.check();
  side = geometry::boundingBoxSize(mesh).maxCoeff();
  job.structure = builtStructure(request, mesh, job.mesh, sizing, context);
  return mesh;
}

// One more build of `request`'s structure, its remesh aiming at
// `faces`, quietly: what it says is kept in `said`. Empty where it is
// refused. (Its import's seconds are added to `job`'s either way.)
struct AnotherBuild {
  PlannedJob job;
  Sizing sizing;
  geometry::PolygonMesh mesh;
  [[nodiscard]] int panels() const { return static_cast<int>(job.structure.panels.size()); }
};
std::optional<AnotherBuild> anotherBuild(const MakeRequest& request, int faces, PlannedJob& job,
                                         const core::SaidLater& said, const core::WorkContext& context) {
  MakeRequest again = request;
  again.remeshFaces = faces;
  again.adviseWayOut = false;
  AnotherBuild built;
  bool refused = false;
  try {
    double side = 0;
    built.mesh = importedAndBuilt(again, built.job, built.sizing, side, said.context(context, false));
  } catch (const core::UserError&) {
    refused = true;
  }
  job.seconds.import += built.job.seconds.import;
  if (refused) return std::nullopt;
  return built;
}

// `built` kept as the job's: its counts, structure and sizing; what it said, said.
geometry::PolygonMesh kept(AnotherBuild&& built, const core::SaidLater& said, PlannedJob& job, Sizing& sizing,
                           const core::WorkContext& context) {
  said.sayOn(context);
  job.mesh = std::move(built.job.mesh);
  job.structure = std::move(built.job.structure);
  sizing = built.sizing;
  return std::move(built.mesh);
}

// Remeshed to these shares of the faces asked by --panels, in turn, where
// the even triangles of the count asked leave a band without room that no
// mend gives it: another sampling of the surface, within
// kPanelCountTolerance of the count, puts its vertices elsewhere. No try
// begins after kNearbySeconds.
constexpr std::array kNearbyPanelShares{0.97, 1.03, 0.99, 1.01, 0.95, 1.05};
constexpr double kNearbySeconds = 20;

// A build of a nearby count of even triangles, kept with what it said.
struct NearbyBuild {
  AnotherBuild built;
  int faces = 0;
  core::SaidLater said;
};

// Remeshed to `centre` faces times each of kNearbyPanelShares in turn (a
// count in `tried` skipped, and added), each built quietly: the first
// whose panels come within kPanelCountTolerance of --panels N. No try
// begins after kNearbySeconds.
std::optional<NearbyBuild> nearbyBuild(const MakeRequest& request, double centre, std::set<int>& tried, PlannedJob& job,
                                       const core::WorkContext& context) {
  const auto began = std::chrono::steady_clock::now();
  for (const double share : kNearbyPanelShares) {
    context.check();
    const auto faces = static_cast<int>(std::lround(centre * share));
    if (!tried.insert(faces).second) continue;  // (a small count: the same target)
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count() > kNearbySeconds) break;
    context.report({"geometry", fmt::format("trying {} even triangles", faces), 0, 0});
    const core::SaidLater said;
    std::optional<AnotherBuild> built = anotherBuild(request, faces, job, said, context);
    if (!built || !withinPanelCountTolerance(built->panels(), *request.panels)) continue;
    return NearbyBuild{std::move(*built), faces, said};
  }
  return std::nullopt;
}

// A structure refused at --panels N, built of a nearby count of even
// triangles (nearbyBuild()); the first that builds with its panels within
// kPanelCountTolerance of N is kept, and said. (A band's panel is a face; a
// weave's an edge, 3/2 of a closed triangle mesh's faces.)
std::optional<geometry::PolygonMesh> withANearbyPanelCount(const MakeRequest& request, PlannedJob& job, Sizing& sizing,
                                                           const core::WorkContext& context) {
  if (!request.panels || request.remeshFaces) return {};
  const int asked = *request.panels;
  const double centre = asked * (request.structure == geometry::StructureKind::Weave ? 2.0 / 3.0 : 1.0);
  std::set<int> tried{static_cast<int>(std::lround(centre))};
  std::optional<NearbyBuild> nearby = nearbyBuild(request, centre, tried, job, context);
  if (!nearby) return std::nullopt;
  context.note(
      fmt::format("{}: the even triangles for {} panels left a {} without room, or a panel folding, that no mend "
                  "cleared: remeshed again, aiming at {} faces",
                  request.mesh.string(), asked, roomPlace(request.structure), nearby->faces));
  return kept(std::move(nearby->built), nearby->said, job, sizing, context);
}

// A structure (band or weave) built for --panels N with more than kPanelCountTolerance
// more or fewer panels than N (mends collapse faces, a remesh held by creases
// misses its target): remeshed once more, aiming off by the share it missed,
// and built again, quietly; that second build is kept where it comes nearer
// the count asked, else the first nearbyBuild() about that aim within
// kPanelCountTolerance of N, else the first. Says the first build's notes (`first`),
// or the second's, and which was kept.
geometry::PolygonMesh withThePanelCountAsked(const MakeRequest& request, PlannedJob& job, Sizing& sizing,
                                             geometry::PolygonMesh mesh, const core::SaidLater& first,
                                             const core::WorkContext& context) {
  const auto& count = job.mesh.panelCount;
  const int asked = request.panels.value_or(0);
  const auto built = static_cast<int>(job.structure.panels.size());
  if (!request.panels || request.remeshFaces || !count || !count->remeshing.remeshed || built <= 0 ||
      withinPanelCountTolerance(built, asked)) {
    first.sayOn(context);
    return mesh;
  }
  // (The remesher's own count is near the target, not on it, where creases
  // hold vertices; a band's panel is a face, a weave's an edge, its first
  // aim two faces for three panels.)
  const auto faces = static_cast<int>(std::lround(static_cast<double>(count->remeshing.asked) * asked / built));
  const core::SaidLater said;
  std::optional<AnotherBuild> second = anotherBuild(request, faces, job, said, context);
  const std::string name = request.mesh.string();
  if (second && std::abs(second->panels() - asked) < std::abs(built - asked)) {
    context.note(
        fmt::format("{}: the even triangles for {} panels gave {} panels as built: remeshed again, aiming at "
                    "{} faces, which gives {}",
                    name, asked, built, faces, second->panels()));
    return kept(std::move(*second), said, job, sizing, context);
  }
  // (Another sampling about that aim, where the mends of this one took many faces.)
  std::set<int> tried{count->remeshing.asked, faces};
  if (std::optional<NearbyBuild> nearby = nearbyBuild(request, faces, tried, job, context)) {
    context.note(
        fmt::format("{}: the even triangles for {} panels gave {} panels as built: remeshed again, aiming at "
                    "{} faces, which gives {}",
                    name, asked, built, nearby->faces, nearby->built.panels()));
    return kept(std::move(nearby->built), nearby->said, job, sizing, context);
  }
  first.sayOn(context);
  context.note(
      fmt::format("{}: {} panels as built, not the {} asked; remeshed again, aiming at {} faces, it {}: "
                  "these {} kept",
                  name, built, asked, faces,
                  second ? fmt::format("gave {}", second->panels()) : std::string("was refused"), built));
  return mesh;
}

}  // namespace

geometry::PolygonMesh builtAsAsked(const MakeRequest& request, PlannedJob& job, Sizing& sizing,
                                   const core::WorkContext& context) {
  // (The first build's notes are said once it is kept, or refused; not those of a build thrown away.)
  const core::SaidLater first;
  double side = 0;
  geometry::PolygonMesh mesh;
  try {
    mesh = importedAndBuilt(request, job, sizing, side, first.context(context));
  } catch (const StructureRefused& refused) {
    if (refused.sizeMayHelp && request.adviseWayOut) {
      if (std::optional<geometry::PolygonMesh> nearby = withANearbyPanelCount(request, job, sizing, context)) {
        return std::move(*nearby);
      }
    }
    first.sayOn(context);
    // A refusal offers a way out that was built, never a guess.
    if (refused.tried || !refused.sizeMayHelp || !request.adviseWayOut) throw;
    // (A band's panel is a face, a weave's an edge.)
    const int panels = request.structure == geometry::StructureKind::Weave ? job.mesh.edges : job.mesh.faces;
    throw core::UserError(withTriedWayOut(request, refused, side, panels, context));
  } catch (...) {
    first.sayOn(context);
    throw;
  }
  return withThePanelCountAsked(request, job, sizing, std::move(mesh), first, context);
}

}  // namespace rotafab::jobs::making
