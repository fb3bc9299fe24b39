#include "geometry/FloodFill.h"

#include <fmt/format.h>

#include <queue>
#include <stdexcept>

namespace rotafab::geometry {

int lowestFace(const PolygonMesh& mesh, int up) {
  int lowest = 0;
  for (int f = 1; f < mesh.faceCount(); ++f) {
    if (faceCentroid(mesh, f)[up] < faceCentroid(mesh, lowest)[up]) lowest = f;
  }
  return lowest;
}

FloodFillOrder floodFill(const PolygonMesh& mesh, const RotationSystem& rs, int start, int up) {
  if (start < 0 || start >= mesh.faceCount()) {
    throw std::invalid_argument(
        fmt::format("start face {}: the mesh's faces are numbered 0 to {}", start, mesh.faceCount() - 1));
  }
  FloodFillOrder order;
  order.panelOfFace.assign(mesh.faceCount(), -1);
  std::vector<double> height(mesh.faceCount());
  for (int f = 0; f < mesh.faceCount(); ++f) height[f] = faceCentroid(mesh, f)[up];
  int seed = start;
  while (seed >= 0) {
    std::queue<int> queue;
    queue.push(seed);
    order.panelOfFace[seed] = static_cast<int>(order.faceOfPanel.size());
    order.faceOfPanel.push_back(seed);
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop();
      Dart d = rs.faceDart(f);
      for (size_t side = 0; side < mesh.faces[f].size(); ++side, d = rs.faceNext(d)) {
        const int next = rs.face(RotationSystem::reverse(d));
        if (next < 0 || order.panelOfFace[next] >= 0) continue;
        order.panelOfFace[next] = static_cast<int>(order.faceOfPanel.size());
        order.faceOfPanel.push_back(next);
        queue.push(next);
      }
    }
    seed = -1;  // another piece: its lowest face
    for (int f = 0; f < mesh.faceCount(); ++f) {
      if (order.panelOfFace[f] < 0 && (seed < 0 || height[f] < height[seed])) seed = f;
    }
  }
  return order;
}

}  // namespace rotafab::geometry
