#include "geometry/ConstructionScale.h"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <utility>

namespace rotafab::geometry {

double constructionScale(const PolygonMesh& mesh, std::optional<double> size, std::optional<double> scale,
                         const ParameterNames& names) {
  if (scale) return *scale;
  if (size) {
    Point3 low = mesh.positions.front(), high = mesh.positions.front();
    for (const Point3& p : mesh.positions) low = low.cwiseMin(p), high = high.cwiseMax(p);
    const double largest = (high - low).maxCoeff();
    if (!(largest > 0))
      throw ParameterError(Parameter::Size, names(Parameter::Size) + ": the mesh has no extent to scale");
    return *size / largest;
  }
  std::set<std::pair<int, int>> edges;
  double total = 0;
  for (const auto& face : mesh.faces) {
    for (size_t i = 0; i < face.size(); ++i) {
      const int a = face[i], b = face[(i + 1) % face.size()];
      if (edges.emplace(std::min(a, b), std::max(a, b)).second) total += (mesh.positions[a] - mesh.positions[b]).norm();
    }
  }
  if (edges.empty() || !(total > 0)) throw std::invalid_argument("the mesh has no edge of positive length to scale by");
  return kMeanEdgeInches / (total / static_cast<double>(edges.size()));
}

}  // namespace rotafab::geometry
