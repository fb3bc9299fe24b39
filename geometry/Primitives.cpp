#include "geometry/Primitives.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace rotafab::geometry {

PolygonMesh convexPolytope(const std::vector<Point3>& points) {
  PolygonMesh mesh;
  mesh.positions = points;
  const int n = static_cast<int>(points.size());
  double scale = 0.0;
  for (const auto& p : points) scale = std::max(scale, p.norm());
  const double tolerance = 1e-9 * std::max(scale, 1.0);
  std::set<std::vector<int>> seen;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (int k = j + 1; k < n; ++k) {
        Eigen::Vector3d normal = (points[j] - points[i]).cross(points[k] - points[i]);
        if (normal.norm() < tolerance) continue;
        normal.normalize();
        const double offset = normal.dot(points[i]);
        int above = 0, below = 0;
        std::vector<int> onPlane;
        for (int m = 0; m < n; ++m) {
          const double side = normal.dot(points[m]) - offset;
          if (side > tolerance)
            ++above;
          else if (side < -tolerance)
            ++below;
          else
            onPlane.push_back(m);
        }
        if (above > 0 && below > 0) continue;
        if (!seen.insert(onPlane).second) continue;
        if (above > 0) normal = -normal;  // outward: the side with no points
        // Sort the face's corners counter-clockwise around the outward normal.
        Point3 centre = Point3::Zero();
        for (int m : onPlane) centre += points[m];
        centre /= static_cast<double>(onPlane.size());
        const Eigen::Vector3d axisU = (points[onPlane[0]] - centre).normalized();
        const Eigen::Vector3d axisV = normal.cross(axisU);
        std::sort(onPlane.begin(), onPlane.end(), [&](int a, int b) {
          const Eigen::Vector3d da = points[a] - centre, db = points[b] - centre;
          return std::atan2(da.dot(axisV), da.dot(axisU)) < std::atan2(db.dot(axisV), db.dot(axisU));
        });
        mesh.faces.push_back(onPlane);
      }
    }
  }
  return mesh;
}

namespace {

constexpr double kPhi = std::numbers::phi;

// All sign combinations of (a, b, c), in its three cyclic permutations.
void addCyclicSigned(std::vector<Point3>& out, double a, double b, double c) {
  const std::array<double, 3> base{a, b, c};
  for (int shift = 0; shift < 3; ++shift) {
    for (int signs = 0; signs < 8; ++signs) {
      Point3 p;
      for (int axis = 0; axis < 3; ++axis) {
        const double value = base[(axis + shift) % 3];
        p[axis] = (signs >> axis & 1) ? -value : value;
      }
      if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
    }
  }
}

}  // namespace

PolygonMesh tetrahedron() { return convexPolytope({{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}}); }

PolygonMesh cube() {
  std::vector<Point3> points;
  addCyclicSigned(points, 1, 1, 1);
  return convexPolytope(points);
}

PolygonMesh octahedron() {
  std::vector<Point3> points;
  addCyclicSigned(points, 1, 0, 0);
  return convexPolytope(points);
}

PolygonMesh dodecahedron() {
  std::vector<Point3> points;
  addCyclicSigned(points, 1, 1, 1);
  addCyclicSigned(points, 0, 1 / kPhi, kPhi);
  return convexPolytope(points);
}

PolygonMesh icosahedron() {
  std::vector<Point3> points;
  addCyclicSigned(points, 0, 1, kPhi);
  return convexPolytope(points);
}

PolygonMesh truncatedIcosahedron() {
  // Even permutations of (0, ±1, ±3φ), (±1, ±(2+φ), ±2φ), (±φ, ±2, ±φ³).
  std::vector<Point3> points;
  addCyclicSigned(points, 0, 1, 3 * kPhi);
  addCyclicSigned(points, 1, 2 + kPhi, 2 * kPhi);
  addCyclicSigned(points, kPhi, 2, kPhi * kPhi * kPhi);
  return convexPolytope(points);
}

PolygonMesh torus(int around, int across, double majorRadius, double minorRadius) {
  PolygonMesh mesh;
  for (int i = 0; i < around; ++i) {
    const double u = 2.0 * std::numbers::pi * i / around;
    for (int j = 0; j < across; ++j) {
      const double v = 2.0 * std::numbers::pi * j / across;
      const double ring = majorRadius + minorRadius * std::cos(v);
      mesh.positions.emplace_back(ring * std::cos(u), ring * std::sin(u), minorRadius * std::sin(v));
    }
  }
  auto index = [&](int i, int j) { return (i % around) * across + (j % across); };
  for (int i = 0; i < around; ++i) {
    for (int j = 0; j < across; ++j) {
      mesh.faces.push_back({index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)});
    }
  }
  return mesh;
}

PolygonMesh voxelSurface(int nx, int ny, int nz, const std::function<bool(int, int, int)>& filled) {
  PolygonMesh mesh;
  std::map<std::array<int, 3>, int> vertexAt;
  auto vertex = [&](std::array<int, 3> c) {
    auto [it, inserted] = vertexAt.emplace(c, mesh.vertexCount());
    if (inserted) mesh.positions.emplace_back(c[0], c[1], c[2]);
    return it->second;
  };
  auto inside = [&](int x, int y, int z) {
    return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz && filled(x, y, z);
  };
  for (int x = 0; x < nx; ++x) {
    for (int y = 0; y < ny; ++y) {
      for (int z = 0; z < nz; ++z) {
        if (!inside(x, y, z)) continue;
        for (int axis = 0; axis < 3; ++axis) {
          for (int side = 0; side < 2; ++side) {
            std::array<int, 3> neighbour{x, y, z};
            neighbour[axis] += side ? 1 : -1;
            if (inside(neighbour[0], neighbour[1], neighbour[2])) continue;
            // The face's two in-plane axes, ordered so that (u, v, outward) is right-handed.
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            std::array<int, 3> corner{x, y, z};
            corner[axis] += side;
            std::array<std::array<int, 3>, 4> quad{corner, corner, corner, corner};
            quad[1][u] += 1;
            quad[2][u] += 1;
            quad[2][v] += 1;
            quad[3][v] += 1;
            std::vector<int> face;
            for (const auto& c : quad) face.push_back(vertex(c));
            if (!side) std::reverse(face.begin(), face.end());
            mesh.faces.push_back(face);
          }
        }
      }
    }
  }
  return mesh;
}

PolygonMesh genusTwoSlab() {
  return voxelSurface(5, 3, 1, [](int x, int y, int) { return !(y == 1 && (x == 1 || x == 3)); });
}

PolygonMesh disc(int segments) {
  PolygonMesh mesh;
  mesh.positions.emplace_back(0, 0, 0);
  for (int i = 0; i < segments; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / segments;
    mesh.positions.emplace_back(std::cos(angle), std::sin(angle), 0);
  }
  for (int i = 0; i < segments; ++i) mesh.faces.push_back({0, 1 + i, 1 + (i + 1) % segments});
  return mesh;
}

PolygonMesh moebiusStrip(int segments) {
  PolygonMesh mesh;
  for (int i = 0; i < segments; ++i) {
    const double u = 2.0 * std::numbers::pi * i / segments;
    for (double w : {-0.5, 0.5}) {
      mesh.positions.emplace_back((2.0 + w * std::cos(u / 2)) * std::cos(u), (2.0 + w * std::cos(u / 2)) * std::sin(u),
                                  w * std::sin(u / 2));
    }
  }
  for (int i = 0; i + 1 < segments; ++i) mesh.faces.push_back({2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1});
  // The last quad closes the strip with its two sides exchanged.
  const int last = segments - 1;
  mesh.faces.push_back({2 * last, 1, 0, 2 * last + 1});
  return mesh;
}

}  // namespace rotafab::geometry
