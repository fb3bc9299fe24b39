#include "geometry/RotationSystem.h"

#include <fmt/format.h>

#include <algorithm>

namespace rotafab::geometry {

RotationSystem RotationSystem::fromMesh(const PolygonMesh& mesh) {
  RotationSystem rs;
  rs.vertexCount_ = mesh.vertexCount();
  // Corners in face order; corner c runs from cornerFrom[c] to cornerTo[c].
  std::vector<int> faceStart(mesh.faces.size() + 1, 0);
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    faceStart[f + 1] = faceStart[f] + static_cast<int>(mesh.faces[f].size());
  const int corners = faceStart.back();
  std::vector<int> cornerFrom(corners), cornerTo(corners);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (size_t i = 0; i < face.size(); ++i) {
      cornerFrom[faceStart[f] + i] = face[i];
      cornerTo[faceStart[f] + i] = face[(i + 1) % face.size()];
    }
  }
  // The corners leaving each vertex (compressed rows): finding the twin of
  // u -> v scans v's few outgoing corners, so building stays linear and cache-friendly.
  std::vector<int> outStart(mesh.positions.size() + 1, 0);
  for (int c = 0; c < corners; ++c) ++outStart[cornerFrom[c] + 1];
  for (size_t v = 0; v < mesh.positions.size(); ++v) outStart[v + 1] += outStart[v];
  std::vector<int> outCorners(corners);
  {
    std::vector<int> fill(outStart.begin(), outStart.end() - 1);
    for (int c = 0; c < corners; ++c) outCorners[fill[cornerFrom[c]]++] = c;
  }
  auto cornersFromTo = [&](int u, int v, int& found, int& count) {
    count = 0;
    for (int k = outStart[u]; k < outStart[u + 1]; ++k) {
      if (cornerTo[outCorners[k]] == v) {
        found = outCorners[k];
        ++count;
      }
    }
  };

  rs.origin_.reserve(corners + corners / 8);
  rs.face_.reserve(corners + corners / 8);
  // Edge e gets darts 2e and 2e+1; the first face to use an edge decides which is which.
  std::vector<Dart> dartOfCorner(corners, -1);
  std::vector<int> faceOfCorner(corners);
  for (int f = 0; f < mesh.faceCount(); ++f)
    for (int c = faceStart[f]; c < faceStart[f + 1]; ++c) faceOfCorner[c] = f;
  for (int c = 0; c < corners; ++c) {
    if (dartOfCorner[c] >= 0) continue;
    const int u = cornerFrom[c], v = cornerTo[c];
    int same = -1, sameCount = 0, twin = -1, twinCount = 0;
    cornersFromTo(u, v, same, sameCount);
    cornersFromTo(v, u, twin, twinCount);
    if (sameCount + twinCount > 2) {
      throw InvalidMeshError(
          fmt::format("edge ({}, {}) is shared by more than two faces", std::min(u, v), std::max(u, v)));
    }
    if (sameCount > 1) {
      throw InvalidMeshError(
          fmt::format("edge ({}, {}) is run in the same direction by two faces: the mesh is not consistently oriented",
                      std::min(u, v), std::max(u, v)));
    }
    const Dart d = static_cast<Dart>(rs.origin_.size());
    rs.origin_.insert(rs.origin_.end(), {u, v});
    rs.face_.insert(rs.face_.end(), {faceOfCorner[c], twin >= 0 ? faceOfCorner[twin] : -1});
    dartOfCorner[c] = d;
    if (twin >= 0) dartOfCorner[twin] = reverse(d);
  }
  const int darts = static_cast<int>(rs.origin_.size());
  rs.faceNext_.assign(darts, -1);
  rs.facePrev_.assign(darts, -1);
  rs.twist_.assign(darts / 2, 0);
  rs.outgoing_.assign(mesh.positions.size(), -1);
  rs.faceDart_.resize(mesh.faces.size());
  for (int f = 0; f < mesh.faceCount(); ++f) rs.faceDart_[f] = dartOfCorner[faceStart[f]];
  for (int f = 0; f < mesh.faceCount(); ++f) {
    for (int c = faceStart[f]; c < faceStart[f + 1]; ++c) {
      const Dart next = dartOfCorner[c + 1 < faceStart[f + 1] ? c + 1 : faceStart[f]];
      rs.faceNext_[dartOfCorner[c]] = next;
      rs.facePrev_[next] = dartOfCorner[c];
    }
  }
  // Boundary darts: at a manifold boundary vertex exactly one boundary dart
  // leaves and one arrives; the open-side walk continues from one to the other.
  std::vector<Dart> boundaryFrom(mesh.positions.size(), -1);
  for (Dart d = 0; d < darts; ++d) {
    if (rs.face_[d] >= 0) continue;
    if (boundaryFrom[rs.origin_[d]] >= 0) {
      throw InvalidMeshError(fmt::format("vertex {} lies on two boundary gaps (a bow-tie vertex)", rs.origin_[d]));
    }
    boundaryFrom[rs.origin_[d]] = d;
  }
  for (Dart d = 0; d < darts; ++d) {
    if (rs.face_[d] >= 0) continue;
    const Dart next = boundaryFrom[rs.origin_[reverse(d)]];
    if (next < 0)
      throw InvalidMeshError(fmt::format("vertex {}: a boundary arrives but none leaves", rs.origin_[reverse(d)]));
    rs.faceNext_[d] = next;
    rs.facePrev_[next] = d;
  }
  for (Dart d = 0; d < darts; ++d)
    if (rs.outgoing_[rs.origin_[d]] < 0 || rs.face_[d] < 0) rs.outgoing_[rs.origin_[d]] = d;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (rs.outgoing_[v] < 0) throw InvalidMeshError(fmt::format("vertex {} belongs to no face", v));
  }
  // faceNext is now a permutation, so every rotation is a cycle; at a bow-tie
  // the cycle through outgoing_[v] misses some of v's darts.
  std::vector<int> outDegree(mesh.positions.size(), 0);
  for (Dart d = 0; d < darts; ++d) ++outDegree[rs.origin_[d]];
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (rs.valence(v) != outDegree[v]) {
      throw InvalidMeshError(fmt::format("vertex {} at {} is a bow-tie: its faces form more than one fan", v,
                                         formatPoint(mesh.positions[v])));
    }
  }
  return rs;
}

std::vector<Dart> RotationSystem::dartsAround(int v) const {
  std::vector<Dart> darts;
  const Dart first = outgoing_[v];
  Dart d = first;
  do {
    darts.push_back(d);
    d = rotateBack(d);
  } while (d != first);
  return darts;
}

int RotationSystem::valence(int v) const {
  int count = 0;
  Dart d = outgoing_[v];
  do {
    d = rotate(d);
    ++count;
  } while (d != outgoing_[v]);
  return count;
}

bool RotationSystem::isBoundaryVertex(int v) const { return face_[outgoing_[v]] < 0; }

}  // namespace rotafab::geometry
