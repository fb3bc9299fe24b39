#include "geometry/RotationSystem.h"

#include <fmt/format.h>

#include <algorithm>
#include <unordered_map>

namespace rotafab::geometry {

RotationSystem RotationSystem::fromMesh(const PolygonMesh& mesh) {
  RotationSystem rs;
  rs.vertexCount_ = mesh.vertexCount();
  std::unordered_map<unsigned long long, Dart> dartOf;  // directed (u, v) -> dart
  size_t corners = 0;
  for (const auto& face : mesh.faces) corners += face.size();
  dartOf.reserve(corners);
  auto key = [](int u, int v) { return (static_cast<unsigned long long>(u) << 32) | static_cast<unsigned>(v); };
  rs.origin_.reserve(corners + corners / 8);
  rs.face_.reserve(corners + corners / 8);

  // Edge e gets darts 2e and 2e+1; the first face to use an edge decides which is which.
  std::vector<std::vector<Dart>> faceDarts(mesh.faces.size());
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (size_t i = 0; i < face.size(); ++i) {
      const int u = face[i], v = face[(i + 1) % face.size()];
      if (dartOf.contains(key(u, v))) {
        throw InvalidMeshError(
            fmt::format("edge ({}, {}) is run in the same direction by two faces: the mesh is not "
                        "consistently oriented",
                        std::min(u, v), std::max(u, v)));
      }
      Dart d;
      if (auto twin = dartOf.find(key(v, u)); twin != dartOf.end()) {
        d = reverse(twin->second);
        if (rs.face_[d] >= 0) {
          throw InvalidMeshError(
              fmt::format("edge ({}, {}) is shared by more than two faces", std::min(u, v), std::max(u, v)));
        }
      } else {
        d = static_cast<Dart>(rs.origin_.size());
        rs.origin_.insert(rs.origin_.end(), {u, v});
        rs.face_.insert(rs.face_.end(), {-1, -1});
      }
      rs.face_[d] = f;
      dartOf.emplace(key(u, v), d);
      faceDarts[f].push_back(d);
    }
  }
  const int darts = static_cast<int>(rs.origin_.size());
  rs.faceNext_.assign(darts, -1);
  rs.facePrev_.assign(darts, -1);
  rs.twist_.assign(darts / 2, 0);
  rs.outgoing_.assign(mesh.positions.size(), -1);
  for (const auto& walk : faceDarts) {
    for (size_t i = 0; i < walk.size(); ++i) {
      rs.faceNext_[walk[i]] = walk[(i + 1) % walk.size()];
      rs.facePrev_[walk[(i + 1) % walk.size()]] = walk[i];
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

Dart RotationSystem::findDart(int u, int v) const {
  Dart d = outgoing_[u];
  do {
    if (target(d) == v) return d;
    d = rotate(d);
  } while (d != outgoing_[u]);
  return -1;
}

}  // namespace rotafab::geometry
