#include "daemon/MakeCommand.h"

#include <fmt/format.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <set>
#include <thread>

#include "daemon/CommandSupport.h"
#include "daemon/ExitCode.h"
#include "daemon/ProgressLines.h"
#include "geometry/BandStructure.h"
#include "geometry/FastenerHoles.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshImport.h"
#include "geometry/ObjWriter.h"
#include "geometry/RotationSystem.h"
#include "jobs/AtomicFile.h"
#include "jobs/Manifest.h"
#include "jobs/SheetPlanner.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {
namespace {

struct MakeOptions {
  std::string mesh;
  std::string structure;
  std::string out;
  std::string machine = "workshop-32x18";
  std::string material = "posterboard";
  bool json = false;
  std::string size, fastener, kerf;
  std::optional<double> scale, tension;
  std::string holes = "keep";
  int samples = 8;
  std::optional<int> start;
  std::string up = "y";
  bool scoreFolds = false;
  double seconds = 5.0;
  std::string order = "window";
  int window = 8;
  std::string layout = "nest";
};

// --holes fill: each boundary loop capped by one polygon face, along the
// loop's own walk (so that the cap is oriented like the faces around it).
void capBoundaryLoops(geometry::PolygonMesh& mesh) {
  const auto rs = geometry::RotationSystem::fromMesh(mesh);
  if (mesh.sourceFace.empty()) {
    for (int f = 0; f < mesh.faceCount(); ++f) mesh.sourceFace.push_back(f);
  }
  std::vector<char> walked(rs.dartCount(), 0);
  for (geometry::Dart d = 0; d < rs.dartCount(); ++d) {
    if (!rs.isBoundary(d) || walked[d]) continue;
    std::vector<int> cap;
    for (geometry::Dart e = d; !walked[e]; e = rs.faceNext(e)) {
      walked[e] = 1;
      cap.push_back(rs.origin(e));
    }
    mesh.faces.push_back(std::move(cap));
    mesh.sourceFace.push_back(-1);  // no face of the file: the manifest says "cap"
  }
}

int runMake(const MakeOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  auto seconds = [last = started]() mutable {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - last).count();
    last = now;
    return elapsed;
  };
  const auto progress = [](const std::string& line) { fmt::print(stderr, "make: {}\n", line); };
  return reportingErrors(options.mesh, [&]() -> int {
    try {
      if (options.structure == "weave") {
        throw UserError("--structure weave: plain-woven structures (dissertation ch. IV) are not built yet; use band");
      }
      const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
      const profiles::MachineProfile machine = profiles::findMachine(catalogue, options.machine);
      const profiles::MaterialProfile material = profiles::findMaterial(catalogue, options.material);

      // Import.
      geometry::ImportedMesh imported = geometry::importMesh(options.mesh);
      for (const auto& warning : imported.warnings) fmt::print(stderr, "warning: {}: {}\n", options.mesh, warning);
      geometry::PolygonMesh& mesh = imported.mesh;
      geometry::MeshAnalysis analysis = geometry::analyzeMesh(mesh);
      for (const auto& note : analysis.notes) fmt::print(stderr, "note: {}: {}\n", options.mesh, note);
      try {
        geometry::requireUsable(analysis);
      } catch (const geometry::InvalidMeshError& error) {
        throw UserError(fmt::format("{}: {}", options.mesh, error.what()));
      }
      if (analysis.topology.boundaryLoops > 0) {
        const int loops = analysis.topology.boundaryLoops;
        if (options.holes == "error") {
          throw UserError(fmt::format("{}: the surface is open ({} boundary loop{}); --holes keep or fill builds it",
                                      options.mesh, loops, loops == 1 ? "" : "s"));
        }
        if (options.holes == "fill") {
          capBoundaryLoops(mesh);
          analysis = geometry::analyzeMesh(mesh);
          try {
            geometry::requireUsable(analysis);
          } catch (const geometry::InvalidMeshError& error) {
            throw UserError(fmt::format("{}: with its {} hole{} filled: {}", options.mesh, loops, loops == 1 ? "" : "s",
                                        error.what()));
          }
          progress(fmt::format("filled {} hole{} with one face each", loops, loops == 1 ? "" : "s"));
        }
      }
      // The mesh as built (after --holes fill): one panel per face.
      const geometry::MeshTopology topology = analysis.topology;
      const double scale = geometry::constructionScale(
          mesh, options.size.empty() ? std::nullopt : std::optional(lengthOption(options.size, "--size", true)),
          options.scale);
      if (!(scale > 0) || !std::isfinite(scale)) throw UserError("--scale: expected a positive number");
      for (geometry::Point3& p : mesh.positions) p *= scale;
      const double importSeconds = seconds();

      // Geometry.
      geometry::BandOptions band;
      band.tension = options.tension;
      band.samples = options.samples;
      band.fastener =
          options.fastener.empty() ? material.fastenerDiameter : lengthOption(options.fastener, "--fastener", true);
      band.start = options.start;
      band.up = options.up == "x" ? 0 : options.up == "y" ? 1 : 2;
      band.scoreFolds = options.scoreFolds;
      band.progress = progress;
      geometry::BandStructure structure;
      try {
        structure = geometry::buildBandStructure(mesh, band);
      } catch (const geometry::NoRoomForHoleError& error) {
        // The same advice as the options that give it: the largest side --size needs.
        Eigen::AlignedBox3d box;
        for (const geometry::Point3& p : mesh.positions) box.extend(p);
        std::string advice = "use a smaller --fastener or a larger --size";
        if (std::isfinite(error.scaleNeeded)) {
          // --scale excludes --size: advise the option the user gave.
          const std::string larger =
              options.scale ? fmt::format("--scale {:.4g}", *options.scale * error.scaleNeeded)
                            : fmt::format("--size {:.0f}in", std::ceil(box.sizes().maxCoeff() * error.scaleNeeded));
          const double smaller = std::floor(band.fastener / error.scaleNeeded * 1000) / 1000;
          advice = smaller > 0
                       ? fmt::format("--fastener {:.3f}in or smaller, or {} or larger, would give every band room",
                                     smaller, larger)
                       : fmt::format("{} or larger would give every band room", larger);
        }
        throw UserError(fmt::format("{}: {}; {}", options.mesh, error.bandsWithoutRoom, advice));
      } catch (const std::invalid_argument& error) {
        throw UserError(fmt::format("{}: {}", options.mesh, error.what()));
      }
      for (const auto& warning : structure.warnings) fmt::print(stderr, "warning: {}: {}\n", options.mesh, warning);
      const double geometrySeconds = seconds();

      // Nesting.
      jobs::PlanOptions plan;
      plan.kerf = options.kerf.empty() ? material.kerf : lengthOption(options.kerf, "--kerf");
      plan.seconds = options.seconds;
      plan.order = options.order == "strict" ? jobs::OrderMode::Strict
                   : options.order == "free" ? jobs::OrderMode::Free
                                             : jobs::OrderMode::Window;
      plan.window = options.window;
      plan.rows = options.layout == "rows";
      plan.title = fmt::format("{} (band)", std::filesystem::path(options.mesh).stem().string());
      core::Executor executor(std::max(1u, std::thread::hardware_concurrency()));
      core::Cancellation cancellation;
      ProgressLineOptions lines;
      lines.prefix = "make: ";
      lines.nestingPrefix = "nesting: ";
      lines.seconds = options.seconds;
      lines.bed = fmt::format("{} x {} in", machine.bed.width, machine.bed.height);
      lines.rows = plan.rows;
      const core::WorkContext context(executor, cancellation, ProgressLines(lines));
      progress(fmt::format("{} {} panels on {} x {} in beds", plan.rows ? "laying out in rows" : "nesting",
                           structure.panels.size(), machine.bed.width, machine.bed.height));
      const std::vector<jobs::Part> parts = jobs::bandParts(structure);
      jobs::SheetPlan sheets;
      try {
        sheets = jobs::planSheets(parts, machine, plan, context);
      } catch (const std::invalid_argument& error) {
        throw UserError(fmt::format("{}: {}", options.mesh, error.what()));
      }
      const double nestingSeconds = seconds();

      // Writing.
      const std::filesystem::path out =
          options.out.empty() ? std::filesystem::path(std::filesystem::path(options.mesh).stem().string() + "-band")
                              : std::filesystem::path(options.out);
      progress(fmt::format("writing {} sheets to {}", sheets.sheets.size(), out.string()));
      // Everything is written into a hidden folder inside `out` first (the
      // same file system, whatever links lead there), and moves in only when
      // all is written: a failure leaves the folder as it was. Each new file
      // then replaces its old namesake in one rename, and only after that are
      // the old job's files that the new one does not have (a stale
      // sheet-009.eps beside a new 8-sheet job) removed.
      std::filesystem::path target = out;
      if (target.filename().empty()) target = target.parent_path();  // "dir/"
      std::filesystem::create_directories(target);
      const std::filesystem::path staging = target / fmt::format(".rotafab-partial-{}", ::getpid());
      std::filesystem::remove_all(staging);
      std::filesystem::create_directories(staging);
      struct Cleanup {
        std::filesystem::path folder;
        ~Cleanup() {
          std::error_code ignored;
          std::filesystem::remove_all(folder, ignored);
        }
      } cleanup{staging};
      const auto files = jobs::writeSheets(sheets, staging);
      geometry::PolygonMesh surface;
      for (const geometry::Panel& panel : structure.panels) {
        for (const auto& polygon : panel.surface) {
          std::vector<int> face;
          for (const geometry::Point3& p : polygon) {
            face.push_back(surface.vertexCount());
            surface.positions.push_back(p);
          }
          surface.faces.push_back(std::move(face));
        }
      }
      jobs::writeFileAtomically(staging / "structure.obj", [&](std::ostream& stream) {
        geometry::writeObj(
            stream, surface,
            fmt::format("rotafab band structure of {}: {} panels, inches", options.mesh, structure.panels.size()));
      });
      const nlohmann::ordered_json manifest = jobs::bandManifest(
          structure, {topology.vertices, topology.edges, topology.faces, topology.genus}, machine.bed, sheets, files);
      jobs::writeFileAtomically(staging / "manifest.json", manifest.dump(1) + "\n");
      jobs::writeFileAtomically(staging / "manifest.txt", jobs::manifestText(manifest));
      std::set<std::string> written;
      for (const auto& entry : std::filesystem::directory_iterator(staging)) {
        written.insert(entry.path().filename().string());
      }
      // manifest.json last: until it moves in, the folder's manifest is the old job's.
      for (const std::string& name : written) {
        if (name != "manifest.json") std::filesystem::rename(staging / name, target / name);
      }
      std::filesystem::rename(staging / "manifest.json", target / "manifest.json");
      static const std::regex ours(R"((sheet-\d{3,}\.(eps|svg|dxf))|manifest\.json|manifest\.txt|structure\.obj)");
      for (const auto& entry : std::filesystem::directory_iterator(target)) {
        const std::string name = entry.path().filename().string();
        if (entry.is_regular_file() && std::regex_match(name, ours) && !written.count(name)) {
          std::filesystem::remove(entry.path());
        }
      }
      const double writingSeconds = seconds();

      if (options.json) {
        nlohmann::ordered_json summary = {{"panels", structure.panels.size()},
                                          {"sheets", sheets.sheets.size()},
                                          {"fasteners", structure.fasteners},
                                          {"utilization", sheets.utilization},
                                          {"seconds",
                                           {{"import", importSeconds},
                                            {"geometry", geometrySeconds},
                                            {"nesting", nestingSeconds},
                                            {"writing", writingSeconds}}}};
        std::cout << summary.dump() << '\n';
      } else {
        fmt::print("{}: {} panels on {} sheet{} ({:.1f}% of the usable bed area), {} fasteners; written to {}/\n",
                   options.mesh, structure.panels.size(), sheets.sheets.size(), sheets.sheets.size() == 1 ? "" : "s",
                   100 * sheets.utilization, structure.fasteners, target.string());
        fmt::print("  import {:.2f} s, geometry {:.2f} s, nesting {:.2f} s, writing {:.2f} s\n", importSeconds,
                   geometrySeconds, nestingSeconds, writingSeconds);
        fmt::print("  assembly: {}/manifest.txt (or `rotafab manifest {}`)\n", target.string(), target.string());
      }
      return kSuccess;
    } catch (const geometry::InvalidMeshError& error) {
      fmt::print(stderr, "error: {}\n", error.what());
      return kUserError;
    } catch (const std::bad_alloc&) {
      fmt::print(stderr, "error: {}: the structure does not fit in memory\n", options.mesh);
      return kUserError;
    }
  });
}

int runManifest(const std::string& folder, const std::string& format) {
  try {
    std::filesystem::path file(folder);
    if (std::filesystem::is_directory(file)) file /= "manifest.json";
    std::ifstream in(file);
    if (!in) throw UserError(fmt::format("{}: cannot read it", file.string()));
    nlohmann::json manifest;
    try {
      manifest = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& error) {
      throw UserError(fmt::format("{}: not JSON: {}", file.string(), error.what()));
    }
    if (format == "json") {
      std::cout << manifest.dump(1) << '\n';
    } else {
      try {
        std::cout << (format == "html" ? jobs::manifestHtml(manifest, file.parent_path())
                                       : jobs::manifestText(manifest));
      } catch (const std::invalid_argument& error) {
        throw UserError(fmt::format("{}: {}", file.string(), error.what()));
      }
    }
    return kSuccess;
  } catch (const UserError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  }
}

}  // namespace

void addMakeCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<MakeOptions>();
  CLI::App* make = app.add_subcommand("make", "Turn a mesh into numbered, drilled panels on laser sheets");
  make->add_option("MESH", options->mesh, "Mesh file: OBJ, OFF, PLY, STL, glTF/GLB, 3MF, ...")->required();
  make->add_option("--structure", options->structure, "band (dissertation ch. V) or weave (ch. IV)")
      ->required()
      ->check(CLI::IsMember({"band", "weave"}));
  make->add_option("--out", options->out, "Output folder (default: MESHNAME-band)");
  make->add_option("--machine", options->machine, "Machine profile: the bed, margins and colours")
      ->capture_default_str();
  make->add_option("--material", options->material, "Material profile: kerf and fastener diameter")
      ->capture_default_str();
  make->add_flag("--json", options->json,
                 "Print one JSON object: panels, sheets, fasteners, utilization, seconds per phase");
  auto* size = make->add_option("--size", options->size, "Scale so that the largest bounding-box side is this long");
  make->add_option("--scale", options->scale, "Scale the mesh by this factor (inches per mesh unit)")->excludes(size);
  make->add_option("--holes", options->holes, "Open meshes: keep the boundary open, fill each hole, or refuse")
      ->capture_default_str()
      ->check(CLI::IsMember({"keep", "fill", "error"}));
  make->add_option("--tension", options->tension,
                   "Corner-cutting tension a of eq. 5.2, 0 < a < 1 (default: Doo-Sabin, a = 1/4 + 5/(4N))");
  make->add_option("--samples", options->samples, "Segments along each edge band")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  make->add_option("--fastener", options->fastener, "Fastener hole diameter (default: the material's, 1/8 in)");
  make->add_option("--kerf", options->kerf, "Kerf (default: the material's)");
  make->add_option("--start", options->start, "Flood-fill start face (index in the file; default: the lowest face)");
  make->add_option("--up", options->up, "The vertical axis, for the lowest face")
      ->capture_default_str()
      ->check(CLI::IsMember({"x", "y", "z"}));
  make->add_flag("--score-folds", options->scoreFolds, "Score the folds between each vertex band and its bands");
  make->add_option("--time", options->seconds, "Nesting improvement budget in seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  make->add_option("--order", options->order, "Cutting order: strict, window or free (see `rotafab nest`)")
      ->capture_default_str()
      ->check(CLI::IsMember({"strict", "window", "free"}));
  make->add_option("--window", options->window, "With --order window: at most this many places from the assembly order")
      ->capture_default_str();
  make->add_option("--layout", options->layout,
                   "nest (true shapes, interlocking) or rows (boxes in rows, in assembly order, on more sheets: a "
                   "quick preview; --order, --window and --time do not apply)")
      ->capture_default_str()
      ->check(CLI::IsMember({"nest", "rows"}));
  make->footer(
      "Writes into the output folder: sheet-001.eps/.svg/.dxf, ... (one set per sheet), manifest.json (SPEC),\n"
      "manifest.txt (the assembly steps), structure.obj (the panels in 3D). Lengths take in, mm or cm.\n"
      "Default scale: the mean edge becomes 2 in.\n\n"
      "Examples:\n"
      "  rotafab make examples/bunny.obj --structure band\n"
      "  rotafab make examples/torus.obj --structure band --size 30in --fastener 3mm --out torus/");
  make->callback([options, &status] { status = runMake(*options); });

  auto folder = std::make_shared<std::string>();
  auto format = std::make_shared<std::string>("text");
  CLI::App* manifest = app.add_subcommand("manifest", "Print the assembly manifest of a `make` output folder");
  manifest->add_option("DIR", *folder, "The output folder of `rotafab make` (or its manifest.json)")->required();
  manifest
      ->add_option("--format", *format, "text (the steps), json (manifest.json) or html (steps and sheets, to print)")
      ->capture_default_str()
      ->check(CLI::IsMember({"text", "json", "html"}));
  manifest->footer(
      "Examples:\n"
      "  rotafab manifest bunny-band/\n"
      "  rotafab manifest bunny-band/ --format html > bunny.html");
  manifest->callback([folder, format, &status] { status = runManifest(*folder, *format); });
}

}  // namespace rotafab::cli
