#pragma once
// The steps of make's pipeline (MakeJob.h) that have files of their own:
// the mesh's preparation (MeshPreparation.cpp) and the structure built at
// the size asked or chosen (StructureSizing.cpp); the pipeline itself is
// MakeJob.cpp. Not an interface of its own: MakeJob.h is.

#include <cmath>
#include <optional>
#include <string>

#include "core/UserError.h"
#include "core/WorkContext.h"
#include "geometry/PolygonMesh.h"
#include "geometry/Structure.h"
#include "jobs/MakeJob.h"
#include "jobs/Manifest.h"

namespace rotafab::jobs::making {

inline const char* plural(int n) { return n == 1 ? "" : "s"; }

// What has room for its fastener, or not: a band decomposition's band, a
// plain weave's crossing.
inline const char* roomPlace(geometry::StructureKind kind) {
  return kind == geometry::StructureKind::Weave ? "crossing" : "band";
}

// The mesh as read, checked, repaired, merged and remeshed as asked, its
// holes filled if asked, at construction size; `counts` says what it was and what was done.
geometry::PolygonMesh importedMesh(const MakeRequest& request, BuiltMesh& counts, const core::WorkContext& context);

// How the structure's size was chosen, when make chose it.
struct Sizing {
  double grown = 1;  // times the default size (1: as it was)
};

// The sides of the box of the structure as built (its panels in 3D).
geometry::Point3 builtSize(const geometry::Structure& structure);

// What to add to a refusal when the mesh's holes were capped with one face
// each: such a cap across a wide or bent hole folds back over its
// neighbours or makes panels as wide as the hole, and a patch avoids it.
std::string oneFaceCapAdvice(const MakeRequest& request, const geometry::PolygonMesh& mesh);

// The structure asked for, a band decomposition (dissertation ch. V) or a
// plain-woven structure (ch. IV), of the mesh as built, at the size asked
// (--size, the structure's largest side as built, within half a percent;
// --scale exactly) or the default, grown by at most 10% where that alone
// gives every band room for its fastener (every crossing for its holes).
// A label that fits nowhere counts as its band or crossing without room. A band or crossing still
// without room, or a woven panel folding over itself at its own edge, has
// its short edge or a sliver beside it collapsed (MeshMending.h; not with
// --keep-faces), recorded among `built`'s repairs, and so has an edge a
// remesh or a mend folded flat; a weave not cleared that way is mended
// again from the design as drawn, a flip first. Where no mend gives a band
// or crossing room, it is glued with --glue-narrow, or make stops with the
// size and the fastener at which it builds as drawn; panels still folding
// stop it with the advice of fewer, evener faces.
// `built.start`: the band flood fill's first face.
geometry::Structure builtStructure(const MakeRequest& request, geometry::PolygonMesh& mesh, BuiltMesh& built,
                                   Sizing& sizing, const core::WorkContext& context);

// The panels of a structure built for --panels N may differ from N by
// this share at most: the mends of narrow bands collapse faces, and a panel
// that would overlap itself is split in two.
inline constexpr double kPanelCountTolerance = 0.05;
inline bool withinPanelCountTolerance(double panels, int asked) {
  return std::abs(panels - asked) <= kPanelCountTolerance * asked;
}

// The mesh imported and its structure built, as make builds it (the import
// and geometry phases; `job`'s mesh counts, structure and import seconds
// filled in). With --panels N, a structure whose panels are more than
// kPanelCountTolerance more or fewer than N (its mends collapse faces,
// creases hold the remesh off its target) is remeshed once more, aiming off
// by that share (and about that aim, at nearby counts, where it misses
// again); one refused for bands or crossings without room, or panels
// folding, is tried at nearby counts of even triangles, within that share
// of N, before the refusal. Only
// the build kept says its notes. A refusal is a UserError naming a way out
// that was built (request.adviseWayOut). Returns the mesh as built.
geometry::PolygonMesh builtAsAsked(const MakeRequest& request, PlannedJob& job, Sizing& sizing,
                                   const core::WorkContext& context);

// builtStructure()'s refusal: the mesh and the place (`place`: "the edge
// between vertices 14 and 12: its band ... has no room ..."), and the way out
// it offers, which `tried` says was built (a size, a fastener) or only
// estimated or not found. `sizeMayHelp`: bands without room or a panel that
// overlaps itself, which a size or a panel count may mend (not a bad
// --start, nor a face far from planar).
class StructureRefused : public core::UserError {
 public:
  StructureRefused(const std::string& mesh, std::string place, std::string advice, bool tried, bool sizeMayHelp = true)
      : core::UserError(mesh + ": " + place + (advice.empty() ? "" : "; " + advice)),
        place(std::move(place)),
        advice(std::move(advice)),
        tried(tried),
        sizeMayHelp(sizeMayHelp) {}
  std::string place, advice;
  bool tried, sizeMayHelp;
};

// A way out of `refused` that was tried: make run again, quietly, with a
// larger size, fewer panels or both (each as the user would ask for it on
// the command line), until one builds with every band fastened and every
// label etched and every panel on the bed; no try begins after
// kWayOutSeconds. Returns the refusal's line with that way out, or with
// what was tried in vain and for how long.
std::string withTriedWayOut(const MakeRequest& request, const StructureRefused& refused, double sideAsRefused,
                            int facesAsRefused, const core::WorkContext& context);

}  // namespace rotafab::jobs::making
