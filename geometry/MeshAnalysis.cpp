#include "geometry/MeshAnalysis.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <queue>
#include <unordered_map>

#include "geometry/EdgeUses.h"

namespace rotafab::geometry {
namespace {

// Messages name elements as the file numbers them.
struct ElementNames {
  const PolygonMesh& mesh;

  [[nodiscard]] int vertex(int v) const { return mesh.sourceVertexIndex(v); }
  [[nodiscard]] int face(int f) const { return mesh.sourceFaceIndex(f); }
  [[nodiscard]] std::string vertices(const std::vector<int>& indices) const {
    std::vector<int> names;
    for (int v : indices) names.push_back(vertex(v));
    return formatIndexList(names);
  }
};

// Reports the faces that visit a vertex more than once and the faces of zero
// area. Returns, per face, whether it visits a vertex more than once.
std::vector<char> reportFaceProblems(const PolygonMesh& mesh, const ElementNames& names,
                                     std::vector<MeshProblem>& problems) {
  const double diagonal = boundingBoxDiagonal(mesh);
  std::vector<char> faceHasRepeat(mesh.faces.size(), 0);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    std::vector<int> sorted = face;
    std::sort(sorted.begin(), sorted.end());
    if (auto repeat = std::adjacent_find(sorted.begin(), sorted.end()); repeat != sorted.end()) {
      faceHasRepeat[f] = 1;
      problems.push_back({MeshProblemKind::RepeatedCorner, fmt::format("face {} visits vertex {} more than once",
                                                                       names.face(f), names.vertex(*repeat))});
    }
    if (fanArea(mesh, f) <= 1e-12 * diagonal * diagonal) {
      problems.push_back(
          {MeshProblemKind::ZeroAreaFace,
           fmt::format("face {} has zero area (its corners {} are collinear)", names.face(f), names.vertices(face))});
    }
  }
  return faceHasRepeat;
}

// Faces joined by a two-sided edge, and whether their orientations agree there.
struct FaceAdjacency {
  int face, neighbour;
  bool agree;
  int low, high;
};

// What the sides of the edges tell about the surface around them.
struct EdgeSides {
  EdgeSides(const PolygonMesh& mesh, int cornerCount)
      : fans(cornerCount),
        vertexComponents(mesh.positions.size()),
        onBoundary(mesh.positions.size(), 0),
        onBadEdge(mesh.positions.size(), 0),
        adjacency(mesh.faces.size()) {}

  DisjointSets fans;  // corners around a vertex joined across shared edges
  DisjointSets vertexComponents;
  std::vector<EdgeUse> boundaryUses;  // the one side of each boundary edge
  std::vector<char> onBoundary, onBadEdge;
  std::vector<std::vector<FaceAdjacency>> adjacency;  // per face
};

// Counts the edges and sorts them by their number of sides: boundary edges,
// two-sided edges (joining fans and faces across them), and non-manifold
// edges, which are reported unless a face running the edge twice explains them.
EdgeSides classifyEdges(const PolygonMesh& mesh, const EdgeUses& edgeUses, const std::vector<char>& faceHasRepeat,
                        const ElementNames& names, MeshAnalysis& analysis) {
  const std::vector<EdgeUse>& uses = edgeUses.uses;
  EdgeSides sides(mesh, edgeUses.cornerCount());
  for (size_t begin = 0; begin < uses.size();) {
    size_t end = begin;
    while (end < uses.size() && uses[end].low == uses[begin].low && uses[end].high == uses[begin].high) ++end;
    const EdgeUse& first = uses[begin];
    ++analysis.topology.edges;
    sides.vertexComponents.unite(first.low, first.high);
    const size_t count = end - begin;
    if (count == 1) {
      sides.onBoundary[first.low] = sides.onBoundary[first.high] = 1;
      sides.boundaryUses.push_back(first);
    } else if (count == 2 && uses[begin].face != uses[begin + 1].face) {
      const EdgeUse& second = uses[begin + 1];
      for (int v : {first.low, first.high}) sides.fans.unite(edgeUses.cornerAt(first, v), edgeUses.cornerAt(second, v));
      const bool agree = first.forward != second.forward;
      sides.adjacency[first.face].push_back({first.face, second.face, agree, first.low, first.high});
      sides.adjacency[second.face].push_back({second.face, first.face, agree, first.low, first.high});
    } else if (count > 2) {
      std::vector<int> faces;
      bool explainedByRepeat = false;  // a face running the edge twice is reported as such
      for (size_t i = begin; i < end; ++i) {
        faces.push_back(names.face(uses[i].face));
        explainedByRepeat = explainedByRepeat || faceHasRepeat[uses[i].face];
      }
      sides.onBadEdge[first.low] = sides.onBadEdge[first.high] = 1;
      if (!explainedByRepeat) {
        analysis.problems.push_back(
            {MeshProblemKind::NonManifoldEdge,
             fmt::format("edge ({}, {}) is shared by {} faces {}",
                         std::min(names.vertex(first.low), names.vertex(first.high)),
                         std::max(names.vertex(first.low), names.vertex(first.high)), count, formatIndexList(faces))});
      }
    }
    begin = end;
  }
  return sides;
}

// Bow-tie vertices: the faces around a vertex must form a single fan.
void reportBowTieVertices(const PolygonMesh& mesh, const EdgeUses& edgeUses, const std::vector<char>& faceHasRepeat,
                          EdgeSides& sides, const ElementNames& names, std::vector<MeshProblem>& problems) {
  std::vector<int> fanCount(mesh.positions.size(), 0);
  std::vector<int> seenRoot(edgeUses.cornerCount(), 0);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (faceHasRepeat[f]) continue;
    for (size_t i = 0; i < mesh.faces[f].size(); ++i) {
      const int corner = edgeUses.firstCorner[f] + static_cast<int>(i);
      const int root = sides.fans.find(corner);
      if (!seenRoot[root]) {
        seenRoot[root] = 1;
        ++fanCount[mesh.faces[f][i]];
      }
    }
  }
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (fanCount[v] > 1 && !sides.onBadEdge[v]) {
      problems.push_back(
          {MeshProblemKind::BowTieVertex, fmt::format("vertex {} at {} is a bow-tie: its faces form {} separate fans",
                                                      names.vertex(v), formatPoint(mesh.positions[v]), fanCount[v])});
    }
  }
}

// The consistent orientation of each component of faces (joined by two-sided edges).
struct Orientation {
  std::vector<int> flip;           // per face: 1 to reverse it against the input
  std::vector<int> faceComponent;  // per face
  int componentCount = 0;
};

// Orientation: breadth-first over faces; a neighbour across an edge both
// faces run the same way must be flipped relative to its parent. Reports the
// first conflict of each non-orientable component, and leaves it as it came.
Orientation orientConsistently(const PolygonMesh& mesh, const std::vector<std::vector<FaceAdjacency>>& adjacency,
                               const ElementNames& names, MeshAnalysis& analysis) {
  Orientation orientation;
  std::vector<int>& flip = orientation.flip;
  std::vector<int>& faceComponent = orientation.faceComponent;
  flip.assign(mesh.faces.size(), -1);
  faceComponent.assign(mesh.faces.size(), -1);
  analysis.topology.orientable = true;
  for (int start = 0; start < mesh.faceCount(); ++start) {
    if (flip[start] >= 0) continue;
    const int component = orientation.componentCount++;
    std::vector<int> members{start};
    flip[start] = 0;
    faceComponent[start] = component;
    bool conflictReported = false;
    for (size_t next = 0; next < members.size(); ++next) {
      const int f = members[next];
      for (const FaceAdjacency& a : adjacency[f]) {
        const int wanted = a.agree ? flip[f] : 1 - flip[f];
        if (flip[a.neighbour] < 0) {
          flip[a.neighbour] = wanted;
          faceComponent[a.neighbour] = component;
          members.push_back(a.neighbour);
        } else if (flip[a.neighbour] != wanted && !conflictReported) {
          conflictReported = true;
          analysis.topology.orientable = false;
          analysis.problems.push_back(
              {MeshProblemKind::NonOrientable,
               fmt::format("the surface is not orientable (a Moebius-like band): faces {} and {} cannot be oriented "
                           "consistently across edge ({}, {})",
                           names.face(f), names.face(a.neighbour), std::min(names.vertex(a.low), names.vertex(a.high)),
                           std::max(names.vertex(a.low), names.vertex(a.high)))});
        }
      }
    }
    if (conflictReported) {
      for (int f : members) flip[f] = 0;  // leave a non-orientable piece as it came
      continue;
    }
    // Keep the orientation most faces already have.
    const auto flipped = std::count_if(members.begin(), members.end(), [&](int f) { return flip[f] == 1; });
    if (2 * flipped > static_cast<long>(members.size()))
      for (int f : members) flip[f] = 1 - flip[f];
  }
  return orientation;
}

// A closed orientable component faces outwards: its enclosed volume, with
// the consistent orientation applied, is positive. Returns, per component,
// whether it must be reversed to face outwards.
std::vector<char> closedComponentsFacingInwards(const PolygonMesh& mesh, const Orientation& orientation,
                                                const std::vector<char>& onBoundary) {
  const int componentCount = orientation.componentCount;
  std::vector<char> reverseComponent(componentCount, 0);
  std::vector<double> volume(componentCount, 0.0);
  std::vector<char> closed(componentCount, 1);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (int v : face)
      if (onBoundary[v]) closed[orientation.faceComponent[f]] = 0;
    const Point3& p0 = mesh.positions[face[0]];
    double sixVolume = 0.0;
    for (size_t i = 1; i + 1 < face.size(); ++i) {
      sixVolume += p0.dot(mesh.positions[face[i]].cross(mesh.positions[face[i + 1]]));
    }
    volume[orientation.faceComponent[f]] += orientation.flip[f] ? -sixVolume : sixVolume;
  }
  for (int c = 0; c < componentCount; ++c) reverseComponent[c] = closed[c] && volume[c] < 0.0;
  return reverseComponent;
}

// Apply, and say what changed against the input, face by face.
void applyOrientation(PolygonMesh& mesh, const Orientation& orientation, const std::vector<char>& reverseComponent,
                      MeshAnalysis& analysis) {
  const std::vector<int>& flip = orientation.flip;
  const std::vector<int>& faceComponent = orientation.faceComponent;
  int consistencyFlips = 0, reversedComponents = 0;
  std::vector<char> hadRelativeFlips(orientation.componentCount, 0);
  for (int f = 0; f < mesh.faceCount(); ++f) hadRelativeFlips[faceComponent[f]] |= flip[f];
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (flip[f] != reverseComponent[faceComponent[f]]) {
      std::reverse(mesh.faces[f].begin(), mesh.faces[f].end());
      if (analysis.flippedFaces++ == 0) analysis.firstFlippedFace = f;
      if (hadRelativeFlips[faceComponent[f]]) ++consistencyFlips;
    }
  }
  for (int c = 0; c < orientation.componentCount; ++c)
    reversedComponents += reverseComponent[c] && !hadRelativeFlips[c];
  if (consistencyFlips > 0) {
    analysis.notes.push_back(fmt::format("flipped {} face{} to make the orientation consistent", consistencyFlips,
                                         consistencyFlips == 1 ? "" : "s"));
  }
  if (reversedComponents > 0) {
    analysis.notes.push_back(fmt::format("reversed all faces of {} closed component{} so that they face outwards",
                                         reversedComponents, reversedComponents == 1 ? "" : "s"));
  }
}

// Boundary loops, as a walk along the boundary would find them: two boundary
// edges continue each other at a vertex only within the same fan there, so a
// bow-tie vertex where two holes touch keeps them apart. Each loop counts
// towards its component's `chiPlusLoops`.
void countBoundaryLoops(const EdgeUses& edgeUses, EdgeSides& sides, const std::vector<int>& componentOf,
                        MeshTopology& topology, std::vector<long long>& chiPlusLoops) {
  const std::vector<EdgeUse>& boundaryUses = sides.boundaryUses;
  DisjointSets loops(boundaryUses.size());
  std::unordered_map<long long, int> edgeAtFan;  // fan (root corner) -> a boundary edge in it
  for (int b = 0; b < static_cast<int>(boundaryUses.size()); ++b) {
    for (int v : {boundaryUses[b].low, boundaryUses[b].high}) {
      auto [it, inserted] = edgeAtFan.emplace(sides.fans.find(edgeUses.cornerAt(boundaryUses[b], v)), b);
      if (!inserted) loops.unite(b, it->second);
    }
  }
  for (int b = 0; b < static_cast<int>(boundaryUses.size()); ++b) {
    if (loops.find(b) != b) continue;
    ++topology.boundaryLoops;
    ++chiPlusLoops[componentOf[boundaryUses[b].low]];
  }
}

// Counts per connected component (through shared vertices): components,
// boundary loops, the Euler characteristic and, on an orientable manifold, the genus.
void countComponentsAndGenus(const PolygonMesh& mesh, const EdgeUses& edgeUses, EdgeSides& sides,
                             MeshTopology& topology) {
  const std::vector<EdgeUse>& uses = edgeUses.uses;
  for (const auto& face : mesh.faces)
    for (size_t i = 1; i < face.size(); ++i) sides.vertexComponents.unite(face[0], face[i]);
  std::vector<int> componentOf(mesh.positions.size());
  std::vector<int> componentIndex(mesh.positions.size(), -1);
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const int root = sides.vertexComponents.find(v);
    if (componentIndex[root] < 0) componentIndex[root] = topology.components++;
    componentOf[v] = componentIndex[root];
  }
  std::vector<long long> chiPlusLoops(topology.components, 0);  // V - E + F + B per component
  for (int v = 0; v < mesh.vertexCount(); ++v) ++chiPlusLoops[componentOf[v]];
  countBoundaryLoops(edgeUses, sides, componentOf, topology, chiPlusLoops);
  for (size_t begin = 0, end = 0; begin < uses.size(); begin = end) {
    while (end < uses.size() && uses[end].low == uses[begin].low && uses[end].high == uses[begin].high) ++end;
    --chiPlusLoops[componentOf[uses[begin].low]];
  }
  for (const auto& face : mesh.faces) ++chiPlusLoops[componentOf[face[0]]];
  topology.euler = topology.vertices - topology.edges + topology.faces;
  if (topology.manifold && topology.orientable) {
    long long genus = 0;
    for (long long chi : chiPlusLoops) genus += (2 - chi) / 2;
    topology.genus = static_cast<int>(genus);
  }
}

}  // namespace

MeshAnalysis analyzeMesh(PolygonMesh& mesh) {
  MeshAnalysis analysis;
  MeshTopology& topology = analysis.topology;
  topology.vertices = mesh.vertexCount();
  topology.faces = mesh.faceCount();
  const ElementNames names{mesh};
  const EdgeUses edgeUses(mesh);

  const std::vector<char> faceHasRepeat = reportFaceProblems(mesh, names, analysis.problems);
  EdgeSides sides = classifyEdges(mesh, edgeUses, faceHasRepeat, names, analysis);
  reportBowTieVertices(mesh, edgeUses, faceHasRepeat, sides, names, analysis.problems);
  topology.manifold = std::none_of(analysis.problems.begin(), analysis.problems.end(), [](const MeshProblem& p) {
    return p.kind == MeshProblemKind::NonManifoldEdge || p.kind == MeshProblemKind::BowTieVertex ||
           p.kind == MeshProblemKind::RepeatedCorner;
  });

  const Orientation orientation = orientConsistently(mesh, sides.adjacency, names, analysis);
  std::vector<char> reverseComponent(orientation.componentCount, 0);
  if (topology.manifold && topology.orientable) {
    reverseComponent = closedComponentsFacingInwards(mesh, orientation, sides.onBoundary);
  }
  applyOrientation(mesh, orientation, reverseComponent, analysis);

  countComponentsAndGenus(mesh, edgeUses, sides, topology);
  return analysis;
}

void requireUsable(const MeshAnalysis& analysis) {
  if (analysis.usable()) return;
  const size_t more = analysis.problems.size() - 1;
  throw InvalidMeshError(more == 0 ? analysis.problems.front().message
                                   : fmt::format("{} (and {} more problem{}; `rotafab inspect` lists them)",
                                                 analysis.problems.front().message, more, more == 1 ? "" : "s"));
}

}  // namespace rotafab::geometry
