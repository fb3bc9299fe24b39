#include "daemon/MakeOptions.h"

#include <fmt/format.h>

#include <cstdlib>
#include <vector>

#include "daemon/CommandSupport.h"

namespace rotafab::cli {

jobs::MakeRequest requestOf(const MakeOptions& options, const profiles::ProfileCatalogue& catalogue) {
  jobs::MakeRequest request;
  request.mesh = options.mesh;
  request.structure = options.structure == "weave" ? geometry::StructureKind::Weave : geometry::StructureKind::Band;
  request.machine = profiles::findMachine(catalogue, options.machine);
  request.material = profiles::findMaterial(catalogue, options.material);
  if (!options.size.empty()) request.size = lengthOption(options.size, "--size", true);
  request.scale = options.scale;
  // SPEC: fill by default for weave (every edge is crossed), keep for band.
  const std::string holes = !options.holes.empty()                                ? options.holes
                            : request.structure == geometry::StructureKind::Weave ? "fill"
                                                                                  : "keep";
  request.holes = holes == "fill"    ? jobs::HolesMode::Fill
                  : holes == "patch" ? jobs::HolesMode::Patch
                  : holes == "error" ? jobs::HolesMode::Error
                                     : jobs::HolesMode::Keep;
  request.repair = options.repair == "auto";
  request.mergeCoplanar = options.mergeCoplanar;
  request.panels = options.panels;
  request.tension = options.tension;
  request.samples = options.samples;
  if (!options.fastener.empty()) request.fastener = lengthOption(options.fastener, "--fastener", true);
  request.start = options.start;
  request.up = options.up == "x" ? 0 : options.up == "y" ? 1 : 2;
  request.scoreFolds = options.scoreFolds;
  request.width = options.width;
  if (options.curve) request.curve = *options.curve;
  if (!options.offset.empty()) request.offset = lengthOption(options.offset, "--offset", true);
  request.cycles = options.cycles == "single" ? geometry::WeaveCycles::Single : geometry::WeaveCycles::All;
  if (!options.kerf.empty()) request.kerf = lengthOption(options.kerf, "--kerf");
  request.seconds = options.seconds;
  request.evaluations = options.evaluations;
  request.order = orderOption(options.order);
  request.freeOrderWhenItSavesSheets = !options.orderGiven;
  request.window = options.window;
  request.rows = options.layout == "rows";
  if (!options.formats.empty()) request.formats = jobs::formatsOf(options.formats);  // checked by --formats
  request.names = flagOf;
  return request;
}

namespace {

const std::vector<std::string> kWeaveOnly{"--width", "--curve", "--offset", "--cycles"};
const std::vector<std::string> kBandOnly{"--tension", "--start", "--score-folds"};
constexpr int kLeastWeaveSamples = 4;

// A fraction of an edge's region: more than 0, at most 1, with no unit.
CLI::Validator fractionCheck() {
  return CLI::Validator(
      [](std::string& value) {
        char* end = nullptr;
        const double number = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0') {
          return fmt::format(
              "{}: expected a plain number more than 0 and at most 1 (a share of the edge's region, "
              "no unit)",
              value);
        }
        if (!(number > 0 && number <= 1)) return fmt::format("{}: expected more than 0 and at most 1", value);
        return std::string();
      },
      "0<F<=1");
}

}  // namespace

void checkStructureOptions(const CLI::App& make, const MakeOptions& options) {
  const bool weave = options.structure == "weave";
  for (const std::string& option : weave ? kBandOnly : kWeaveOnly) {
    if (make.count(option) > 0) {
      throw CLI::ValidationError(
          weave ? fmt::format("{} is an option of the band decomposition (--structure band), not of weave", option)
                : fmt::format("{} is an option of the plain-woven structure (--structure weave), not of band", option));
    }
  }
  if (weave && options.samples < kLeastWeaveSamples) {
    throw CLI::ValidationError(fmt::format(
        "--samples {}: a weave needs at least {} (its panels run half a Bézier segment past each crossing under, to "
        "hold its holes)",
        options.samples, kLeastWeaveSamples));
  }
  if (weave && options.holes == "keep") {
    throw CLI::ValidationError(
        "--holes keep: a plain weave crosses every edge, and a boundary edge has one side; fill (the default for "
        "weave) caps each hole with a face, patch closes it with triangles like the mesh's own, error refuses an "
        "open mesh");
  }
}

void addMakeOptions(CLI::App& make, MakeOptions& options) {
  make.add_option("MESH", options.mesh, "Mesh file: OBJ, OFF, PLY, STL, glTF/GLB, 3MF, ...")->required();
  make.add_option("--structure", options.structure, "band (dissertation ch. V) or weave (ch. IV)")
      ->required()
      ->check(CLI::IsMember({"band", "weave"}));
  make.add_option("--out", options.out, "Output folder (default: MESHNAME-STRUCTURE, e.g. bunny-band)")
      ->check(outputFolderCheck());
  make.add_option("--machine", options.machine, "Machine profile: the bed, margins and colours")->capture_default_str();
  make.add_option("--material", options.material, "Material profile: kerf and fastener diameter")
      ->capture_default_str();
  make.add_flag("--json", options.json,
                "Print one JSON object: panels, sheets, fasteners, utilization, seconds per phase");
  auto* size = make.add_option("--size", options.size, "Scale so that the largest bounding-box side is this long");
  make.add_option("--scale", options.scale, "Scale the mesh by this factor (inches per mesh unit)")->excludes(size);
  make.add_option("--holes", options.holes,
                  "Open meshes: keep the boundary open (the default for band), fill each hole with one face (the "
                  "default for weave), patch it with triangles as long as its edges (for a wide or bent hole, "
                  "whose one face would make a weave's panels as wide as the hole), or error: refuse")
      ->check(CLI::IsMember({"keep", "fill", "patch", "error"}));
  make.add_option("--repair", options.repair,
                  "auto: weld, drop duplicate faces, split non-manifold edges and bow-tie vertices, orient (each "
                  "repair said and recorded in manifest.json); none: refuse a broken mesh")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "none"}));
  make.add_option("--merge-coplanar", options.mergeCoplanar,
                  "Merge adjacent faces within this many degrees of one plane into one panel (default: 1 for STL, "
                  "whose faces are all triangles; 0 for other formats)")
      ->check(CLI::Range(0.0, 45.0));
  make.add_option("--panels", options.panels,
                  "Simplify the mesh to about this many faces, one panel each (quadric edge collapse that keeps the "
                  "shape, the genus and the boundary; polygons become triangles)")
      ->check(CLI::Range(4, 10000000));
  make.add_option("--tension", options.tension,
                  "Corner-cutting tension a of eq. 5.2, 0 < a < 1 (default: Doo-Sabin, a = 1/4 + 5/(4N))");
  make.add_option("--samples", options.samples,
                  "Segments along each edge band (band), or along each ribbon's Bézier curve between crossings "
                  "(weave)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  make.add_option("--width", options.width,
                  "Weave: the ribbons' share of their edge region across them, 0 < W <= 1 (eq. 4.6-4.9; default\n"
                  "0.8, narrowed edge by edge where ribbons would pass through each other; a W given is kept)")
      ->check(fractionCheck());
  make.add_option("--curve", options.curve,
                  "Weave: each crossing's share of its edge region along the ribbon, 0 < C <= 1 (default 0.6;\n"
                  "smaller curves the ribbons more between crossings; eq. 4.2-4.5)")
      ->check(fractionCheck());
  make.add_option("--offset", options.offset,
                  "Weave: how far a ribbon stands over (or under) the surface at a crossing (default: half the\n"
                  "material's thickness, at least 0.01in)");
  make.add_option("--cycles", options.cycles,
                  "Weave: all (every edge crossed: a thread per Petrie walk) or single (one thread weaves the\n"
                  "whole object, crossing the edges of a spanning tree of the dual)")
      ->capture_default_str()
      ->check(CLI::IsMember({"all", "single"}));
  make.add_option("--fastener", options.fastener, "Fastener hole diameter (default: the material's, 1/8 in)");
  make.add_option("--kerf", options.kerf, "Kerf (default: the material's)");
  make.add_option("--start", options.start, "Flood-fill start face (index in the file; default: the lowest face)");
  make.add_option("--up", options.up, "The vertical axis, for the lowest face")
      ->capture_default_str()
      ->check(CLI::IsMember({"x", "y", "z"}));
  make.add_flag("--score-folds", options.scoreFolds, "Score the folds between each vertex band and its bands");
  make.add_option("--time", options.seconds,
                  "Nesting time budget in seconds, first layout included: the best layout found\n"
                  "by then is kept; parts the first layout has not reached by then go in rows (with a note)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  make.add_option("--evaluations", options.evaluations,
                  "Stop the nesting's searches after this many layouts each, the first included: with a --time\n"
                  "long enough, the same sheets on every machine of as many cores (1: the first layout only)")
      ->check(CLI::Range(0, 1000000000));
  make.add_option("--order", options.order,
                  "Cutting order: strict, window or free (see `rotafab nest`); by default window, or free where\n"
                  "keeping to the window would cost a sheet")
      ->each([&options](const std::string&) { options.orderGiven = true; })
      ->capture_default_str()
      ->check(CLI::IsMember({"strict", "window", "free"}));
  make.add_option("--window", options.window, "With --order window: at most this many places from the assembly order")
      ->capture_default_str();
  make.add_option("--layout", options.layout,
                  "nest (true shapes, interlocking) or rows (boxes in rows, in assembly order, on more sheets: a "
                  "quick preview; --order, --window and --time do not apply)")
      ->capture_default_str()
      ->check(CLI::IsMember({"nest", "rows"}));
  make.add_option("--formats", options.formats,
                  "Sheet files to write, of eps, svg and dxf, e.g. eps,svg,dxf (default: eps,svg, and dxf where the\n"
                  "machine profile's `formats` names it); `rotafab run` and the daemon cut from the SVG")
      ->check(CLI::Validator(
          [](std::string& value) {
            try {
              jobs::formatsOf(value);
              return std::string();
            } catch (const std::invalid_argument& error) {
              return std::string(error.what());
            }
          },
          "eps,svg,dxf"));
}

}  // namespace rotafab::cli
