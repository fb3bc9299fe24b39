#include "geometry/HoleFilling.h"

#include <vector>

#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

int fillHoles(PolygonMesh& mesh) {
  const auto rs = RotationSystem::fromMesh(mesh);
  if (mesh.sourceFace.empty()) {
    for (int f = 0; f < mesh.faceCount(); ++f) mesh.sourceFace.push_back(f);
  }
  int caps = 0;
  std::vector<char> walked(rs.dartCount(), 0);
  for (Dart d = 0; d < rs.dartCount(); ++d) {
    if (!rs.isBoundary(d) || walked[d]) continue;
    std::vector<int> cap;
    for (Dart e = d; !walked[e]; e = rs.faceNext(e)) {
      walked[e] = 1;
      cap.push_back(rs.origin(e));
    }
    mesh.faces.push_back(std::move(cap));
    mesh.sourceFace.push_back(-1);  // no face of the file: the manifest says "cap"
    ++caps;
  }
  return caps;
}

}  // namespace rotafab::geometry
