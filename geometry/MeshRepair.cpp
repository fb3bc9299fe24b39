#include "geometry/MeshRepair.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

#include "geometry/EdgeUses.h"
#include "geometry/MeshMending.h"
#include "geometry/io/MeshImport.h"

namespace rotafab::geometry {
namespace {

// Vertices within this share of the box's diagonal are one: far below any
// edge a builder could cut, above the noise of a float written and read back.
constexpr double kWeldTolerance = 1e-6;

std::string vertexName(const PolygonMesh& mesh, int v) { return fmt::format("vertex {}", mesh.sourceVertexIndex(v)); }
std::string faceName(const PolygonMesh& mesh, int f) { return fmt::format("face {}", mesh.sourceFaceIndex(f)); }

// Welds vertices closer than the tolerance to an earlier one (a grid of cells
// the tolerance wide: a near vertex is in the same cell or a neighbouring one).
void weldNear(PolygonMesh& mesh, std::vector<MeshRepair>& repairs) {
  const double tolerance = kWeldTolerance * boundingBoxDiagonal(mesh);
  if (!(tolerance > 0)) return;
  using Cell = std::array<long long, 3>;
  struct CellHash {
    size_t operator()(const Cell& c) const {
      // Unsigned: wraps where a signed product would overflow (a small part far from the origin).
      return static_cast<size_t>(static_cast<unsigned long long>(c[0]) * 73856093ULL ^
                                 static_cast<unsigned long long>(c[1]) * 19349663ULL ^
                                 static_cast<unsigned long long>(c[2]) * 83492791ULL);
    }
  };
  std::unordered_map<Cell, std::vector<int>, CellHash> cells;
  cells.reserve(mesh.positions.size());
  auto cellOf = [&](const Point3& p) {
    return Cell{static_cast<long long>(std::floor(p.x() / tolerance)),
                static_cast<long long>(std::floor(p.y() / tolerance)),
                static_cast<long long>(std::floor(p.z() / tolerance))};
  };
  // Where each vertex goes (itself, or the earlier vertex it is welded to).
  std::vector<int> target(mesh.positions.size());
  std::iota(target.begin(), target.end(), 0);
  std::vector<std::vector<int>> facesOf;  // made when first needed
  // Whether welding v onto w would make a face visit w twice: v and a corner
  // that is, or goes to, w are in one face and not neighbours there. (Two
  // neighbours welded make the face one corner shorter, which is fine.)
  auto wouldPinch = [&](int v, int w) {
    if (facesOf.empty()) {
      facesOf.resize(mesh.positions.size());
      for (int f = 0; f < mesh.faceCount(); ++f)
        for (int corner : mesh.faces[f]) facesOf[corner].push_back(f);
    }
    for (int f : facesOf[v]) {
      const auto& corners = mesh.faces[f];
      const size_t n = corners.size();
      for (size_t i = 0; i < n; ++i) {
        if (corners[i] != v) continue;
        for (size_t j = 0; j < n; ++j) {
          if (j != i && j != (i + 1) % n && j != (i + n - 1) % n && target[corners[j]] == w) return true;
        }
      }
    }
    return false;
  };
  int welded = 0, firstWelded = -1;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const Cell cell = cellOf(mesh.positions[v]);
    int onto = -1;
    for (long long dx = -1; dx <= 1 && onto < 0; ++dx)
      for (long long dy = -1; dy <= 1 && onto < 0; ++dy)
        for (long long dz = -1; dz <= 1 && onto < 0; ++dz) {
          const auto it = cells.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == cells.end()) continue;
          for (int w : it->second) {
            if ((mesh.positions[w] - mesh.positions[v]).norm() <= tolerance && !wouldPinch(v, w)) {
              onto = w;
              break;
            }
          }
        }
    if (onto < 0) {
      cells[cell].push_back(v);
      continue;
    }
    if (firstWelded < 0) firstWelded = v;
    ++welded;
    target[v] = onto;
    mesh.positions[v] = mesh.positions[onto];  // cleanMesh() welds identical positions
  }
  if (welded == 0) return;
  const std::string first = vertexName(mesh, firstWelded);
  const int facesBefore = mesh.faceCount();
  std::vector<int> sourcesBefore(mesh.faceCount());
  for (int f = 0; f < mesh.faceCount(); ++f) sourcesBefore[f] = mesh.sourceFaceIndex(f);
  cleanMesh(mesh);
  repairs.push_back({"weld", welded, first});
  if (const int collapsed = facesBefore - mesh.faceCount(); collapsed > 0) {
    // The first face that went: the first source index missing from what is kept.
    std::vector<int> kept(mesh.faceCount());
    for (int f = 0; f < mesh.faceCount(); ++f) kept[f] = mesh.sourceFaceIndex(f);
    std::sort(kept.begin(), kept.end());
    int gone = sourcesBefore.front();
    for (int source : sourcesBefore) {
      if (!std::binary_search(kept.begin(), kept.end(), source)) {
        gone = source;
        break;
      }
    }
    repairs.push_back({"drop-collapsed-face", collapsed, fmt::format("face {}", gone)});
  }
}

// The face's corners from its lowest vertex, in the direction whose second
// corner is lower: the same for the same cycle whichever way it runs.
std::vector<int> canonicalCycle(const std::vector<int>& face) {
  const size_t n = face.size();
  const size_t low = static_cast<size_t>(std::min_element(face.begin(), face.end()) - face.begin());
  const bool forward = face[(low + 1) % n] <= face[(low + n - 1) % n];
  std::vector<int> cycle(n);
  for (size_t i = 0; i < n; ++i) cycle[i] = face[forward ? (low + i) % n : (low + n - i) % n];
  return cycle;
}

void dropDuplicateFaces(PolygonMesh& mesh, std::vector<MeshRepair>& repairs) {
  std::map<std::vector<int>, int> seen;
  std::vector<char> duplicate(mesh.faces.size(), 0);
  int count = 0, firstDuplicate = -1;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (!seen.emplace(canonicalCycle(mesh.faces[f]), f).second) {
      duplicate[f] = 1;
      if (count++ == 0) firstDuplicate = f;
    }
  }
  if (count == 0) return;
  repairs.push_back({"drop-duplicate-face", count, faceName(mesh, firstDuplicate)});
  std::vector<std::vector<int>> faces;
  std::vector<int> sources;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (duplicate[f]) continue;
    faces.push_back(std::move(mesh.faces[f]));
    sources.push_back(mesh.sourceFaceIndex(f));
  }
  mesh.faces = std::move(faces);
  mesh.sourceFace = std::move(sources);
}

bool visitsAVertexTwice(std::vector<int> face) {
  std::sort(face.begin(), face.end());
  return std::adjacent_find(face.begin(), face.end()) != face.end();
}

// Cuts edges of more than two faces open and gives each fan of faces around
// a vertex its own copy of it. Corners (face, position) around a vertex are
// joined across every edge of exactly two faces; each class of corners is a
// fan. An edge of more than two faces joins nothing, so its faces meet again
// only where they share a fan at both ends.
// Edge sides with no other side: the open boundary.
int loneSides(const EdgeUses& edges) {
  int lone = 0;
  edges.forEachEdge([&](size_t begin, size_t end) { lone += end - begin == 1; });
  return lone;
}

void splitFans(PolygonMesh& mesh, std::vector<MeshRepair>& repairs) {
  const EdgeUses edges(mesh);
  DisjointSets fans(edges.cornerCount());
  std::vector<char> onCutEdge(mesh.positions.size(), 0);
  int cutEdges = 0;
  std::string firstCut;
  edges.forEachEdge([&](size_t begin, size_t end) {
    const EdgeUse& a = edges.uses[begin];
    if (end - begin == 2 && edges.uses[begin + 1].face != a.face) {
      for (int v : {a.low, a.high}) fans.unite(edges.cornerAt(a, v), edges.cornerAt(edges.uses[begin + 1], v));
    } else if (end - begin > 2) {
      onCutEdge[a.low] = onCutEdge[a.high] = 1;
      if (cutEdges++ == 0) {
        const int x = mesh.sourceVertexIndex(a.low), y = mesh.sourceVertexIndex(a.high);
        firstCut = fmt::format("edge ({}, {})", std::min(x, y), std::max(x, y));
      }
    }
  });
  // The first fan of a vertex keeps it; every other fan gets a copy.
  std::vector<int> fanVertex(edges.cornerCount(), -1);  // by root corner
  std::vector<char> hasFan(mesh.positions.size(), 0);
  int bowTies = 0, firstBowTie = -1;
  std::vector<char> countedBowTie(mesh.positions.size(), 0);
  if (mesh.sourceVertex.empty()) {
    mesh.sourceVertex.resize(mesh.positions.size());
    std::iota(mesh.sourceVertex.begin(), mesh.sourceVertex.end(), 0);
  }
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (visitsAVertexTwice(mesh.faces[f])) continue;  // left to the analysis, which refuses it
    for (size_t i = 0; i < mesh.faces[f].size(); ++i) {
      const int root = fans.find(edges.firstCorner[f] + static_cast<int>(i));
      int& v = mesh.faces[f][i];
      if (fanVertex[root] < 0) {
        if (!hasFan[v]) {
          hasFan[v] = 1;
          fanVertex[root] = v;
        } else {
          if (!onCutEdge[v] && !countedBowTie[v]) {
            countedBowTie[v] = 1;
            if (bowTies++ == 0) firstBowTie = v;
          }
          fanVertex[root] = mesh.vertexCount();
          mesh.positions.push_back(mesh.positions[v]);
          mesh.sourceVertex.push_back(mesh.sourceVertex[v]);
        }
      }
      v = fanVertex[root];
    }
  }
  if (cutEdges > 0) {
    const int loneSidesBefore = loneSides(edges);
    // Where no two faces at a cut edge share a fan at both of its ends, their
    // sides stay open (an inner wall between two closed parts): say how many.
    MeshRepair cut{"split-nonmanifold-edge", cutEdges, firstCut};
    // Only cut edges change their count of sides: the rise in sides with no
    // partner is theirs.
    cut.leftOpen = loneSides(EdgeUses(mesh)) - loneSidesBefore;
    repairs.push_back(cut);
  }
  if (bowTies > 0) repairs.push_back({"split-bowtie", bowTies, vertexName(mesh, firstBowTie)});
}

}  // namespace

std::string MeshRepair::line(core::LengthUnit unit) const {
  const bool one = count == 1;
  std::string what;
  if (kind == "weld") {
    what =
        fmt::format("welded {} vert{} to a nearer neighbour than 1e-6 of the mesh's size", count, one ? "ex" : "ices");
  } else if (kind == "drop-collapsed-face") {
    what = fmt::format("dropped {} face{} that the weld collapsed", count, one ? "" : "s");
  } else if (kind == "drop-duplicate-face") {
    what = fmt::format("dropped {} duplicate face{}", count, one ? "" : "s");
  } else if (kind == "split-nonmanifold-edge") {
    what = fmt::format("split {} edge{} shared by more than two faces", count, one ? "" : "s");
  } else if (kind == "split-bowtie") {
    what = fmt::format("split {} bow-tie vert{} into one copy per fan of faces", count, one ? "ex" : "ices");
  } else if (kind == "orient") {
    what = fmt::format("reversed {} face{} to orient the surface consistently and outwards", count, one ? "" : "s");
  } else if (kind == "collapse-degenerate-face") {
    what = fmt::format("collapsed {} face{} of zero area (collinear corners) into {} neighbours", count, one ? "" : "s",
                       one ? "its" : "their");
  } else if (kind == "merge-narrow-band") {
    what = fmt::format(
        "merged the two faces beside {} edge{} whose band or crossing was too narrow for a fastener or "
        "its number into one face each",
        count, one ? "" : "s");
  } else if (kind == "flip-narrow-band") {
    what = fmt::format(
        "flipped {} edge{} of a sliver beside a band or crossing too narrow for a fastener or its number, or "
        "a panel folding",
        count, one ? "" : "s");
  } else if (kind == "collapse-short-edge") {
    what = fmt::format(
        "collapsed {} short edge{} or sliver{} whose band or crossing had no room for a fastener or "
        "its number, or whose panel folded",
        count, one ? "" : "s", one ? "" : "s");
  } else {
    what = fmt::format("{}: {}", kind, count);
  }
  // (Two significant digits at least: a mend may move it by a hair.)
  const int decimals = moved > 0 ? std::max(2, 2 - static_cast<int>(std::floor(std::log10(moved)))) : 2;
  if (moved > 0) what += fmt::format(", moving the surface at most {}", unit(moved, std::min(decimals, 9)));
  std::string open;
  if (leftOpen > 0) {
    open = fmt::format("; {} side{} of them left open, where no two faces belonged together", leftOpen,
                       leftOpen == 1 ? "" : "s");
  }
  return fmt::format("{} (the first: {}){}", what, first, open);
}

std::vector<MeshRepair> repairMesh(PolygonMesh& mesh) {
  std::vector<MeshRepair> repairs;
  weldNear(mesh, repairs);
  dropDuplicateFaces(mesh, repairs);
  splitFans(mesh, repairs);
  if (MeshRepair degenerate = collapseDegenerateFaces(mesh); degenerate.count > 0) {
    repairs.push_back(std::move(degenerate));
  }
  return repairs;
}

RepairPreview previewRepair(PolygonMesh copy) {
  RepairPreview preview;
  preview.repairs = repairMesh(copy);
  preview.after = analyzeMesh(copy);
  return preview;
}

MeshRepair orientRepair(const MeshAnalysis& analysis, const PolygonMesh& mesh) {
  if (analysis.flippedFaces == 0) return {};
  return {"orient", analysis.flippedFaces, faceName(mesh, analysis.firstFlippedFace)};
}

}  // namespace rotafab::geometry
