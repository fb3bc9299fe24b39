#include "geometry/MeshAnalysis.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <queue>
#include <unordered_map>

#include "geometry/EdgeUses.h"

namespace rotafab::geometry {
MeshAnalysis analyzeMesh(PolygonMesh& mesh) {
  MeshAnalysis analysis;
  MeshTopology& topology = analysis.topology;
  topology.vertices = mesh.vertexCount();
  topology.faces = mesh.faceCount();
  const double diagonal = boundingBoxDiagonal(mesh);

  const EdgeUses edgeUses(mesh);
  const std::vector<EdgeUse>& uses = edgeUses.uses;
  const int cornerCount = edgeUses.cornerCount();

  // Messages name elements as the file numbers them.
  auto vertexName = [&](int v) { return mesh.sourceVertexIndex(v); };
  auto faceName = [&](int f) { return mesh.sourceFaceIndex(f); };
  auto vertexNames = [&](const std::vector<int>& vertices) {
    std::vector<int> names;
    for (int v : vertices) names.push_back(vertexName(v));
    return formatIndexList(names);
  };

  std::vector<char> faceHasRepeat(mesh.faces.size(), 0);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    std::vector<int> sorted = face;
    std::sort(sorted.begin(), sorted.end());
    if (auto repeat = std::adjacent_find(sorted.begin(), sorted.end()); repeat != sorted.end()) {
      faceHasRepeat[f] = 1;
      analysis.problems.push_back(
          {MeshProblemKind::RepeatedCorner,
           fmt::format("face {} visits vertex {} more than once", faceName(f), vertexName(*repeat))});
    }
    if (fanArea(mesh, f) <= 1e-12 * diagonal * diagonal) {
      analysis.problems.push_back(
          {MeshProblemKind::ZeroAreaFace,
           fmt::format("face {} has zero area (its corners {} are collinear)", faceName(f), vertexNames(face))});
    }
  }
  auto cornerAt = [&](const EdgeUse& use, int vertex) { return edgeUses.cornerAt(use, vertex); };

  DisjointSets fans(cornerCount);  // corners around a vertex joined across shared edges
  DisjointSets vertexComponents(mesh.positions.size());
  std::vector<EdgeUse> boundaryUses;  // the one side of each boundary edge
  std::vector<char> onBoundary(mesh.positions.size(), 0), onBadEdge(mesh.positions.size(), 0);
  // Faces joined by a two-sided edge, and whether their orientations agree there.
  struct Adjacency {
    int face, neighbour;
    bool agree;
    int low, high;
  };
  std::vector<std::vector<Adjacency>> adjacency(mesh.faces.size());
  for (size_t begin = 0; begin < uses.size();) {
    size_t end = begin;
    while (end < uses.size() && uses[end].low == uses[begin].low && uses[end].high == uses[begin].high) ++end;
    const EdgeUse& first = uses[begin];
    ++topology.edges;
    vertexComponents.unite(first.low, first.high);
    const size_t count = end - begin;
    if (count == 1) {
      onBoundary[first.low] = onBoundary[first.high] = 1;
      boundaryUses.push_back(first);
    } else if (count == 2 && uses[begin].face != uses[begin + 1].face) {
      const EdgeUse& second = uses[begin + 1];
      for (int v : {first.low, first.high}) fans.unite(cornerAt(first, v), cornerAt(second, v));
      const bool agree = first.forward != second.forward;
      adjacency[first.face].push_back({first.face, second.face, agree, first.low, first.high});
      adjacency[second.face].push_back({second.face, first.face, agree, first.low, first.high});
    } else if (count > 2) {
      std::vector<int> faces;
      bool explainedByRepeat = false;  // a face running the edge twice is reported as such
      for (size_t i = begin; i < end; ++i) {
        faces.push_back(faceName(uses[i].face));
        explainedByRepeat = explainedByRepeat || faceHasRepeat[uses[i].face];
      }
      onBadEdge[first.low] = onBadEdge[first.high] = 1;
      if (!explainedByRepeat) {
        analysis.problems.push_back(
            {MeshProblemKind::NonManifoldEdge,
             fmt::format("edge ({}, {}) is shared by {} faces {}",
                         std::min(vertexName(first.low), vertexName(first.high)),
                         std::max(vertexName(first.low), vertexName(first.high)), count, formatIndexList(faces))});
      }
    }
    begin = end;
  }

  // Bow-tie vertices: the faces around a vertex must form a single fan.
  {
    std::vector<int> fanCount(mesh.positions.size(), 0);
    std::vector<int> seenRoot(cornerCount, 0);
    for (int f = 0; f < mesh.faceCount(); ++f) {
      if (faceHasRepeat[f]) continue;
      for (size_t i = 0; i < mesh.faces[f].size(); ++i) {
        const int corner = edgeUses.firstCorner[f] + static_cast<int>(i);
        const int root = fans.find(corner);
        if (!seenRoot[root]) {
          seenRoot[root] = 1;
          ++fanCount[mesh.faces[f][i]];
        }
      }
    }
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      if (fanCount[v] > 1 && !onBadEdge[v]) {
        analysis.problems.push_back(
            {MeshProblemKind::BowTieVertex, fmt::format("vertex {} at {} is a bow-tie: its faces form {} separate fans",
                                                        vertexName(v), formatPoint(mesh.positions[v]), fanCount[v])});
      }
    }
  }
  topology.manifold = std::none_of(analysis.problems.begin(), analysis.problems.end(), [](const MeshProblem& p) {
    return p.kind == MeshProblemKind::NonManifoldEdge || p.kind == MeshProblemKind::BowTieVertex ||
           p.kind == MeshProblemKind::RepeatedCorner;
  });

  // Orientation: breadth-first over faces; a neighbour across an edge both
  // faces run the same way must be flipped relative to its parent.
  std::vector<int> flip(mesh.faces.size(), -1);
  std::vector<int> faceComponent(mesh.faces.size(), -1);
  topology.orientable = true;
  int componentCount = 0;
  for (int start = 0; start < mesh.faceCount(); ++start) {
    if (flip[start] >= 0) continue;
    const int component = componentCount++;
    std::vector<int> members{start};
    flip[start] = 0;
    faceComponent[start] = component;
    bool conflictReported = false;
    for (size_t next = 0; next < members.size(); ++next) {
      const int f = members[next];
      for (const Adjacency& a : adjacency[f]) {
        const int wanted = a.agree ? flip[f] : 1 - flip[f];
        if (flip[a.neighbour] < 0) {
          flip[a.neighbour] = wanted;
          faceComponent[a.neighbour] = component;
          members.push_back(a.neighbour);
        } else if (flip[a.neighbour] != wanted && !conflictReported) {
          conflictReported = true;
          topology.orientable = false;
          analysis.problems.push_back(
              {MeshProblemKind::NonOrientable,
               fmt::format("the surface is not orientable (a Moebius-like band): faces {} and {} cannot be oriented "
                           "consistently across edge ({}, {})",
                           faceName(f), faceName(a.neighbour), std::min(vertexName(a.low), vertexName(a.high)),
                           std::max(vertexName(a.low), vertexName(a.high)))});
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
  // A closed orientable component faces outwards: its enclosed volume, with
  // the consistent orientation applied, is positive.
  std::vector<char> reverseComponent(componentCount, 0);
  if (topology.manifold && topology.orientable) {
    std::vector<double> volume(componentCount, 0.0);
    std::vector<char> closed(componentCount, 1);
    for (int f = 0; f < mesh.faceCount(); ++f) {
      const auto& face = mesh.faces[f];
      for (int v : face)
        if (onBoundary[v]) closed[faceComponent[f]] = 0;
      const Point3& p0 = mesh.positions[face[0]];
      double sixVolume = 0.0;
      for (size_t i = 1; i + 1 < face.size(); ++i) {
        sixVolume += p0.dot(mesh.positions[face[i]].cross(mesh.positions[face[i + 1]]));
      }
      volume[faceComponent[f]] += flip[f] ? -sixVolume : sixVolume;
    }
    for (int c = 0; c < componentCount; ++c) reverseComponent[c] = closed[c] && volume[c] < 0.0;
  }
  // Apply, and say what changed against the input, face by face.
  int consistencyFlips = 0, reversedComponents = 0;
  std::vector<char> hadRelativeFlips(componentCount, 0);
  for (int f = 0; f < mesh.faceCount(); ++f) hadRelativeFlips[faceComponent[f]] |= flip[f];
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (flip[f] != reverseComponent[faceComponent[f]]) {
      std::reverse(mesh.faces[f].begin(), mesh.faces[f].end());
      if (analysis.flippedFaces++ == 0) analysis.firstFlippedFace = f;
      if (hadRelativeFlips[faceComponent[f]]) ++consistencyFlips;
    }
  }
  for (int c = 0; c < componentCount; ++c) reversedComponents += reverseComponent[c] && !hadRelativeFlips[c];
  if (consistencyFlips > 0) {
    analysis.notes.push_back(fmt::format("flipped {} face{} to make the orientation consistent", consistencyFlips,
                                         consistencyFlips == 1 ? "" : "s"));
  }
  if (reversedComponents > 0) {
    analysis.notes.push_back(fmt::format("reversed all faces of {} closed component{} so that they face outwards",
                                         reversedComponents, reversedComponents == 1 ? "" : "s"));
  }

  // Counts per connected component (through shared vertices).
  for (const auto& face : mesh.faces)
    for (size_t i = 1; i < face.size(); ++i) vertexComponents.unite(face[0], face[i]);
  std::vector<int> componentOf(mesh.positions.size());
  std::vector<int> componentIndex(mesh.positions.size(), -1);
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const int root = vertexComponents.find(v);
    if (componentIndex[root] < 0) componentIndex[root] = topology.components++;
    componentOf[v] = componentIndex[root];
  }
  std::vector<long long> chiPlusLoops(topology.components, 0);  // V - E + F + B per component
  for (int v = 0; v < mesh.vertexCount(); ++v) ++chiPlusLoops[componentOf[v]];
  // Boundary loops, as a walk along the boundary would find them: two boundary
  // edges continue each other at a vertex only within the same fan there, so a
  // bow-tie vertex where two holes touch keeps them apart.
  {
    DisjointSets loops(boundaryUses.size());
    std::unordered_map<long long, int> edgeAtFan;  // fan (root corner) -> a boundary edge in it
    for (int b = 0; b < static_cast<int>(boundaryUses.size()); ++b) {
      for (int v : {boundaryUses[b].low, boundaryUses[b].high}) {
        auto [it, inserted] = edgeAtFan.emplace(fans.find(cornerAt(boundaryUses[b], v)), b);
        if (!inserted) loops.unite(b, it->second);
      }
    }
    for (int b = 0; b < static_cast<int>(boundaryUses.size()); ++b) {
      if (loops.find(b) != b) continue;
      ++topology.boundaryLoops;
      ++chiPlusLoops[componentOf[boundaryUses[b].low]];
    }
  }
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
