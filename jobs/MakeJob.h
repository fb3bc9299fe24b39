#pragma once
// The whole of `rotafab make` (docs/CONTRACT.md, "make") as one call, for the
// command line and the daemon alike: a request in (a mesh file and the
// options), a planned job out (its structure, sheets and files). The phases,
// each reported as progress: import (read, check, fill holes, scale), geometry
// (the structure's builder), nesting (the planner), writing (the output folder,
// by OutputFolder's rule).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/LengthUnit.h"
#include "core/WorkContext.h"
#include "geometry/Parameters.h"
#include "geometry/Stability.h"
#include "geometry/Structure.h"
#include "geometry/WeaveThreads.h"
#include "jobs/JobCost.h"
#include "jobs/Manifest.h"
#include "jobs/Nesting.h"
#include "jobs/Part.h"
#include "jobs/SheetPlanner.h"
#include "profiles/Profiles.h"

namespace rotafab::jobs {

// --holes (docs/CONTRACT.md, "make"): leave the boundary open, cap each hole
// with one face, close it with a patch of triangles like the mesh's own, or
// refuse an open mesh.
enum class HolesMode { Keep, Fill, Patch, Error };

// A woven ribbon's least offset over or under the surface, inches: paper's thickness.
constexpr double kLeastOffset = 0.01;

struct MakeRequest {
  std::filesystem::path mesh;  // messages name it as given
  geometry::StructureKind structure = geometry::StructureKind::Band;
  profiles::MachineProfile machine;
  profiles::MaterialProfile material;
  std::optional<double> size;   // the largest side, inches; or
  std::optional<double> scale;  // inches per mesh unit; neither: the mean edge becomes 2 in
  HolesMode holes = HolesMode::Keep;
  // Adjacent faces within this many degrees of one plane become one face
  // (geometry/CoplanarMerge.h); by default 1 for an STL file (triangles
  // only), off (0) for every other format.
  std::optional<double> mergeCoplanar;
  // Remesh to even triangles that give about this many panels (geometry/Remeshing.h).
  std::optional<int> panels;
  // The faces the remesh aims at, when not `panels`' own: make's second
  // remesh, aiming off by the share the first build missed, and its nearby
  // samplings where the first was refused (making::builtAsAsked, MakeSteps.h).
  std::optional<int> remeshFaces;
  // --repair auto (docs/CONTRACT.md, "Command line"; geometry/MeshRepair.h);
  // false: none, a broken mesh is refused.
  bool repair = true;
  // The band decomposition's options (geometry/BandStructure.h).
  std::optional<double> tension;
  int samples = 8;
  std::optional<double> fastener;  // default: the material's
  std::optional<int> start;
  int up = 1;
  bool scoreFolds = false;
  // No mend of the design (geometry/MeshMending.h): a band without room stops the job.
  bool keepFaces = false;
  // A band without room even after mending is glued, not refused.
  bool glueNarrow = false;
  // A refusal names a way out that was built (a size, a fastener, a panel
  // count: MakeSteps.h); false for make's own tries of one, which need not.
  bool adviseWayOut = true;
  // The plain weave's (geometry/WeaveStructure.h); `samples` too, per Bézier segment.
  std::optional<double> width;  // default: geometry::RibbonShape's, narrowed where ribbons would meet
  double curve = 0.6;
  std::optional<double> offset;  // inches; default: half the material's thickness, at least kLeastOffset
  geometry::WeaveCycles cycles = geometry::WeaveCycles::All;
  // The planner's (jobs/SheetPlanner.h).
  std::optional<double> kerf;  // default: the material's
  double seconds = kDefaultNestingSeconds;
  int evaluations = 0;                  // as NestingOptions'
  std::optional<SheetFormats> formats;  // unset: defaultFormats(machine)
  OrderMode order = OrderMode::Kits;
  int window = 8;
  bool rows = false;
  // How messages name the options (the command line: by their flags).
  geometry::ParameterNames names = geometry::parameterInWords;
  // The unit the summary, manifest.txt, the previews and messages show lengths in.
  core::LengthUnit shownIn;
};

struct PhaseSeconds {
  double import = 0, geometry = 0, nesting = 0, writing = 0;
  double estimate = 0;  // the cutting time's, sheet by sheet (jobCost), between nesting and writing
};

struct PlannedJob {
  std::filesystem::path meshFile;  // as the request named it
  std::string title;               // "bunny (band)"
  BuiltMesh mesh;                  // of the mesh as built (after --holes fill)
  profiles::Bed bed;               // the machine's
  std::string machine, material;   // the profiles' names: manifest.json's "machine" and "material"
  geometry::Structure structure;
  geometry::Stability stability;                     // of the structure as built, standing on the request's up axis
  geometry::Point3 size = geometry::Point3::Zero();  // the mesh's box as built, inches ("size", docs/CONTRACT.md)
  SheetPlan sheets;
  SheetFormats formats;
  JobCost cost;
  core::LengthUnit shownIn;  // the request's: manifest.json's "display_units"
  // What the plan warns of (a band with less clearance, labels that do not
  // fit), as make says it, without the mesh's name: manifest.json's
  // "warnings" and manifest.txt's, before the steps.
  std::vector<std::string> warnings;
  // Once written (writeJob()):
  std::filesystem::path folder;
  std::vector<std::vector<std::string>> files;  // per sheet
  PhaseSeconds seconds;
};

// The coplanar merge's angle when --merge-coplanar is not given: 1 degree for
// an STL file (triangles only), 0 (none) for every other format.
double defaultMergeDegrees(const std::filesystem::path& mesh);

// The output folder when none is given: MESHNAME-band beside where the command runs.
std::filesystem::path defaultOutputFolder(const MakeRequest& request);

// Imports, builds and plans the job, in memory. Throws core::UserError (one
// line naming the mesh file, or an option as `names` calls it),
// geometry::InvalidMeshError (an unreadable mesh, named), core::Cancelled;
// notes and warnings go to the context's logger as they come, each after
// the mesh file's name.
PlannedJob planJob(const MakeRequest& request, const core::WorkContext& context);

// Writes the job into `folder`: sheet-001.eps/.svg/.dxf ..., manifest.json,
// manifest.txt, structure.obj. On any failure or a cancel the folder is left
// as it was. Throws std::runtime_error naming a file that cannot be
// written, core::Cancelled.
void writeJob(PlannedJob& job, const std::filesystem::path& folder, const core::WorkContext& context);

// The summary of a written job (`make --json`; docs/CONTRACT.md, "make"): {"panels", "sheets",
// "fasteners", "utilization", "seconds": {"import", "geometry", "nesting", "estimate", "writing"}},
// and "simplified": {"asked", "faces"} when a panel count was asked, "size": [X, Y, Z] (the
// structure's box, inches), and "stability" (stabilityJson()).
nlohmann::ordered_json summaryJson(const PlannedJob& job);

// planJob() then writeJob().
PlannedJob makeJob(const MakeRequest& request, const std::filesystem::path& folder, const core::WorkContext& context);

}  // namespace rotafab::jobs
