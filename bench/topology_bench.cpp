// Import + analysis + rotation system + face tracing on meshes from 1k to 200k
// faces (the target: linear growth, 2x faces at most 2.2x time).
//
//   build/rotafab_bench                         run the benchmarks
//   build/rotafab_bench write-mesh FACES FILE   write the benchmark's mesh of
//                                               about FACES triangles as OBJ
//
// The meshes are triangulated tori (closed, genus 1, every vertex of valence 6),
// written to OBJ so that the real import path, Assimp included, is measured.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "core/HugePageHeap.h"
#include "geometry/BandStructure.h"
#include "geometry/ConstructionScale.h"
#include "geometry/CoplanarMerge.h"
#include "geometry/FaceTracing.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshRepair.h"
#include "geometry/Primitives.h"
#include "geometry/Remeshing.h"
#include "geometry/WeaveStructure.h"
#include "geometry/io/MeshImport.h"
#include "geometry/io/ObjWriter.h"

namespace geo = rotafab::geometry;

namespace {

// A torus of about `faces` triangles: each quad of a torus grid split in two.
geo::PolygonMesh triangulatedTorus(long faces) {
  const int across = std::max(3, static_cast<int>(std::sqrt(faces / 2.0 / 4.0)));
  const int around = std::max(3, static_cast<int>(faces / 2 / across));
  geo::PolygonMesh quads = geo::torus(around, across);
  geo::PolygonMesh mesh;
  mesh.positions = quads.positions;
  for (const auto& q : quads.faces) {
    mesh.faces.push_back({q[0], q[1], q[2]});
    mesh.faces.push_back({q[0], q[2], q[3]});
  }
  return mesh;
}

// One OBJ file per size, written once and kept for the run.
const std::filesystem::path& meshFile(long faces) {
  static std::map<long, std::filesystem::path> files;
  auto& path = files[faces];
  if (path.empty()) {
    path = std::filesystem::temp_directory_path() / ("rotafab-bench-" + std::to_string(faces) + ".obj");
    std::ofstream out(path, std::ios::binary);
    geo::writeObj(out, triangulatedTorus(faces));
  }
  return path;
}

void sizes(benchmark::internal::Benchmark* b) {
  for (long faces : {1000L, 2000L, 4000L, 8000L, 16000L, 32000L, 64000L, 128000L, 200000L}) b->Arg(faces);
}

void BM_ImportAnalyzeTrace(benchmark::State& state) {
  const auto& path = meshFile(state.range(0));
  long faces = 0;
  rotafab::core::Executor executor(std::max(1u, std::thread::hardware_concurrency()));
  const rotafab::core::Cancellation never;
  const rotafab::core::WorkContext context(executor, never);
  for (auto _ : state) {
    geo::ImportedMesh imported = geo::importMesh(path);
    geo::requireUsable(geo::analyzeMesh(imported.mesh));
    const geo::RotationSystem rs = geo::RotationSystem::fromMesh(imported.mesh);
    const auto walks = geo::traceAllFaces(rs);
    benchmark::DoNotOptimize(walks.data());
    faces = imported.mesh.faceCount();
  }
  state.SetComplexityN(faces);
  state.counters["faces"] = static_cast<double>(faces);
  state.counters["faces/s"] =
      benchmark::Counter(static_cast<double>(faces), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ImportAnalyzeTrace)->Apply(sizes)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

// The stages alone, to see where the time goes.
void BM_Import(benchmark::State& state) {
  const auto& path = meshFile(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(geo::importMesh(path).mesh.faces.data());
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_Import)->Apply(sizes)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

void BM_Analyze(benchmark::State& state) {
  const geo::PolygonMesh mesh = triangulatedTorus(state.range(0));
  for (auto _ : state) {
    geo::PolygonMesh copy = mesh;
    benchmark::DoNotOptimize(geo::analyzeMesh(copy).topology.genus);
  }
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_Analyze)->Apply(sizes)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

// `make --repair auto` (geometry/MeshRepair.h) on the torus with every
// hundredth face given twice, so that each repair step has work. Target:
// linear, under 1 s at 200k faces.
void BM_Repair(benchmark::State& state) {
  geo::PolygonMesh mesh = triangulatedTorus(state.range(0));
  const int faces = mesh.faceCount();
  for (int f = 0; f < faces; f += 100) mesh.faces.push_back(mesh.faces[f]);
  for (auto _ : state) {
    geo::PolygonMesh copy = mesh;
    benchmark::DoNotOptimize(geo::repairMesh(copy).size());
  }
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_Repair)->Apply(sizes)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

// Merging coplanar faces (geometry/CoplanarMerge.h), as an STL gets it, on
// the torus: each pair of triangles merged back into its grid's planar quad.
void BM_MergeCoplanar(benchmark::State& state) {
  const geo::PolygonMesh mesh = triangulatedTorus(state.range(0));
  for (auto _ : state) {
    geo::PolygonMesh copy = mesh;
    benchmark::DoNotOptimize(geo::mergeCoplanarFaces(copy, 1.0).regions);
  }
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_MergeCoplanar)->Apply(sizes)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

// A torus of about `faces` triangles, roughened as a scan is: each vertex
// moved along the tube's radius by up to 1% of it, the same way every run.
geo::PolygonMesh roughTorus(long faces) {
  geo::PolygonMesh mesh = triangulatedTorus(faces);
  unsigned noise = 12345;
  for (geo::Point3& p : mesh.positions) {
    noise = noise * 1103515245u + 12345u;
    const geo::Point3 axis(p.x(), p.y(), 0);
    const geo::Point3 radial = (p - axis.normalized() * 2.0).normalized();  // geo::torus's tube: 2 from the axis
    p += radial * (0.0075 * ((noise >> 16) % 1000) / 1000.0);               // up to 1% of its 0.75 radius
  }
  return mesh;
}

// `make --panels 2000` (geometry/Remeshing.h): the rough torus remeshed to
// 2,000 even triangles. Target: under 3 s at 200k faces.
void BM_Remesh(benchmark::State& state) {
  const geo::PolygonMesh mesh = roughTorus(state.range(0));
  rotafab::core::Executor executor(1);
  const rotafab::core::Cancellation never;
  const rotafab::core::WorkContext context(executor, never);
  for (auto _ : state) {
    geo::PolygonMesh copy = mesh;
    benchmark::DoNotOptimize(geo::remeshEvenly(copy, 2000, context).facesAfter);
  }
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_Remesh)->Arg(8000)->Arg(32000)->Arg(200000)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

void BM_RotationSystemAndTrace(benchmark::State& state) {
  const geo::PolygonMesh mesh = triangulatedTorus(state.range(0));
  for (auto _ : state) {
    const geo::RotationSystem rs = geo::RotationSystem::fromMesh(mesh);
    benchmark::DoNotOptimize(geo::traceAllFaces(rs).size());
  }
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_RotationSystemAndTrace)->Apply(sizes)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oN);

// Import to labelled panels of one structure: import, analysis, scale (mean
// edge 2 in), then `build`.
template <class Build>
void structureFromFile(benchmark::State& state, const Build& build) {
  const auto& path = meshFile(state.range(0));
  long faces = 0;
  rotafab::core::Executor executor(std::max(1u, std::thread::hardware_concurrency()));
  const rotafab::core::Cancellation never;
  const rotafab::core::WorkContext context(executor, never);
  for (auto _ : state) {
    geo::ImportedMesh imported = geo::importMesh(path);
    geo::requireUsable(geo::analyzeMesh(imported.mesh));
    const double scale = geo::constructionScale(imported.mesh, std::nullopt, std::nullopt);
    for (geo::Point3& p : imported.mesh.positions) p *= scale;
    const geo::Structure structure = build(imported.mesh, context);
    benchmark::DoNotOptimize(structure.panels.data());
    faces = imported.mesh.faceCount();
  }
  state.SetComplexityN(faces);
}

// `make --structure band` up to the planner, import to
// labelled panels: import, analysis, scale (mean edge 2 in), vertex bands,
// developable bands, unfolding, holes, labels, flood fill. Target: linear,
// under 5 s for 50k faces. (Nesting is measured by rotafab_nest_bench.)
void BM_BandStructure(benchmark::State& state) {
  structureFromFile(state, [](const geo::PolygonMesh& mesh, const rotafab::core::WorkContext& context) {
    return geo::buildBandStructure(mesh, geo::BandOptions{}, context);
  });
}
BENCHMARK(BM_BandStructure)
    ->Arg(4000)
    ->Arg(8000)
    ->Arg(16000)
    ->Arg(32000)
    ->Arg(50000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

// `make --structure weave` up to the planner, import to labelled panels:
// import, analysis, scale (mean edge 2 in), threads, edge regions,
// ribbons, panels cut and unfolded, holes, labels, assembly order. One panel
// per edge: 1.5 per face of these triangulated tori. Target as for band:
// linear, under 5 s for 50k faces.
void BM_WeaveStructure(benchmark::State& state) {
  structureFromFile(state, [](const geo::PolygonMesh& mesh, const rotafab::core::WorkContext& context) {
    return geo::buildWeaveStructure(mesh, geo::WeaveOptions{}, context);
  });
}
BENCHMARK(BM_WeaveStructure)
    ->Arg(4000)
    ->Arg(8000)
    ->Arg(16000)
    ->Arg(32000)
    ->Arg(50000)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

// The whole pipeline: `rotafab make MESH --structure band
// --layout rows --json`, the program itself, import to written sheets
// (EPS, SVG, DXF), manifest.json, manifest.txt and structure.obj. The time
// is import + geometry + writing as make reports them; the layout is left
// out and reported beside it (`nesting_s`; `--layout rows` keeps it to
// seconds, where true-shape nesting would take minutes).
void BM_MakeBand(benchmark::State& state) {
  const auto& path = meshFile(state.range(0));
  const auto out = std::filesystem::temp_directory_path() / ("rotafab-bench-make-" + std::to_string(state.range(0)));
  const auto summary = out.string() + ".json";
  nlohmann::json seconds;
  for (auto _ : state) {
    const std::string command = std::string(ROTAFAB_CLI) + " make '" + path.string() +
                                "' --structure band --layout rows --json --out '" + out.string() + "' > '" + summary +
                                "' 2>/dev/null";
    if (std::system(command.c_str()) != 0) {
      state.SkipWithError(("failed: " + command).c_str());
      return;
    }
    std::ifstream in(summary);
    const auto result = nlohmann::json::parse(in);
    seconds = result.at("seconds");
    state.SetIterationTime(seconds.at("import").get<double>() + seconds.at("geometry").get<double>() +
                           seconds.at("writing").get<double>());
    state.counters["sheets"] = result.at("sheets").get<double>();
  }
  for (const char* phase : {"import", "geometry", "nesting", "writing"}) {
    state.counters[std::string(phase) + "_s"] = seconds.at(phase).get<double>();
  }
  std::uintmax_t bytes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out)) bytes += entry.file_size();
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
  std::filesystem::remove_all(out);
  std::filesystem::remove(summary);
  state.SetComplexityN(state.range(0));
}
BENCHMARK(BM_MakeBand)
    ->Arg(4000)
    ->Arg(8000)
    ->Arg(16000)
    ->Arg(32000)
    ->Arg(50000)
    ->UseManualTime()
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->Complexity(benchmark::oN);

}  // namespace

int main(int argc, char** argv) {
  // As the program does: the structures' heap in huge pages.
  rotafab::core::startAgainWithHugePageHeap(argv);
  if (argc == 4 && std::string(argv[1]) == "write-mesh") {
    std::ofstream out(argv[3], std::ios::binary);
    geo::writeObj(out, triangulatedTorus(std::stol(argv[2])), "rotafab benchmark mesh: triangulated torus");
    return out ? 0 : 1;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::temp_directory_path())) {
    if (entry.path().filename().string().starts_with("rotafab-bench-")) std::filesystem::remove(entry.path());
  }
  return 0;
}
