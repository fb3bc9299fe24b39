#pragma once
// The Hausdorff distance between two surfaces, for the tests of
// remeshing: the largest distance from a point of either surface to the
// other, measured from a dense set of points on each (every corner, and a
// barycentric grid on every triangle of a fan triangulation of each face) to
// the nearest point of the other's triangles. Written for the tests, apart
// from the code under test: closest point on a triangle by its Voronoi
// regions (Ericson, "Real-Time Collision Detection", 2005, sec. 5.1.5).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "geometry/PolygonMesh.h"

namespace rotafab::test {

using Vec = geometry::Point3;

inline Vec closestOnTriangle(const Vec& p, const Vec& a, const Vec& b, const Vec& c) {
  const Vec ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

struct Triangle {
  Vec a, b, c, centre;
  double radius;  // of a sphere about `centre` holding the triangle
};

inline std::vector<Triangle> trianglesOf(const geometry::PolygonMesh& mesh) {
  std::vector<Triangle> triangles;
  for (const auto& face : mesh.faces) {
    for (size_t i = 1; i + 1 < face.size(); ++i) {
      Triangle t{mesh.positions[face[0]], mesh.positions[face[i]], mesh.positions[face[i + 1]], {}, 0};
      t.centre = (t.a + t.b + t.c) / 3;
      t.radius = std::max({(t.a - t.centre).norm(), (t.b - t.centre).norm(), (t.c - t.centre).norm()});
      triangles.push_back(t);
    }
  }
  return triangles;
}

inline std::vector<Vec> samplesOf(const geometry::PolygonMesh& mesh, int steps) {
  std::vector<Vec> samples(mesh.positions.begin(), mesh.positions.end());
  for (const Triangle& t : trianglesOf(mesh)) {
    for (int i = 0; i <= steps; ++i) {
      for (int j = 0; i + j <= steps; ++j) {
        const double u = double(i) / steps, v = double(j) / steps;
        samples.push_back(t.a + (t.b - t.a) * u + (t.c - t.a) * v);
      }
    }
  }
  return samples;
}

struct SampledDistances {
  double largest = 0;
  double mean = 0;
};

// The largest and the mean distance from a sample of `from` to the surface `to`.
inline SampledDistances sampledDistances(const geometry::PolygonMesh& from, const geometry::PolygonMesh& to,
                                         int steps) {
  const std::vector<Triangle> triangles = trianglesOf(to);
  double largest = 0, sum = 0;
  size_t count = 0;
  size_t hint = 0;  // the last sample's nearest triangle: a good first bound for the next
  for (const Vec& p : samplesOf(from, steps)) {
    double best = (closestOnTriangle(p, triangles[hint].a, triangles[hint].b, triangles[hint].c) - p).norm();
    for (size_t k = 0; k < triangles.size(); ++k) {
      const Triangle& t = triangles[k];
      if ((p - t.centre).norm() - t.radius >= best) continue;  // no point of it is nearer
      const double distance = (closestOnTriangle(p, t.a, t.b, t.c) - p).norm();
      if (distance < best) {
        best = distance;
        hint = k;
      }
    }
    largest = std::max(largest, best);
    sum += best;
    ++count;
  }
  return {largest, count > 0 ? sum / static_cast<double>(count) : 0};
}

// The largest distance from a sample of `from` to the surface `to`.
inline double oneSidedDistance(const geometry::PolygonMesh& from, const geometry::PolygonMesh& to, int steps) {
  return sampledDistances(from, to, steps).largest;
}

inline double hausdorffDistance(const geometry::PolygonMesh& a, const geometry::PolygonMesh& b, int steps = 3) {
  return std::max(oneSidedDistance(a, b, steps), oneSidedDistance(b, a, steps));
}

}  // namespace rotafab::test
