#pragma once
// The nearest point of a surface, for remeshing's projection back onto the
// input (Remeshing.cpp): its triangles, and its feature lines (boundary and
// creases, the edges OpenMesh's status marks as features), each in a
// bounding-volume hierarchy (Eigen's KdBVH). Internal to geometry.

#include <unsupported/Eigen/BVH>

#include <array>
#include <limits>
#include <vector>

#include "geometry/TriangleMeshes.h"

namespace rotafab::geometry::projection {

using triangles::toPoint;
using triangles::TriMesh;
using Box = Eigen::AlignedBox3d;

// The closest point to p of the triangle abc, by its Voronoi regions
// (Ericson, "Real-Time Collision Detection", 2005, sec. 5.1.5).
inline Point3 closestOnTriangle(const Point3& p, const Point3& a, const Point3& b, const Point3& c) {
  const Point3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Point3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Point3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double scale = 1.0 / (va + vb + vc);
  return a + ab * (vb * scale) + ac * (vc * scale);
}

inline Point3 closestOnSegment(const Point3& p, const Point3& a, const Point3& b) {
  const Point3 ab = b - a;
  const double length2 = ab.squaredNorm();
  if (length2 <= 0) return a;
  return a + ab * std::clamp((p - a).dot(ab) / length2, 0.0, 1.0);
}

// The input surface, to project onto: its triangles, and its feature lines
// (boundary and creases), each in a bounding-volume hierarchy (Eigen's
// KdBVH) for the nearest-point queries.
class ReferenceSurface {
 public:
  ReferenceSurface(const TriMesh& tri, const triangles::SourceNumbers& source) {
    for (const auto face : tri.faces()) {
      std::array<Point3, 3> corners;
      int i = 0;
      for (const auto vertex : tri.fv_range(face)) corners[i++] = toPoint(tri.point(vertex));
      triangles_.push_back(corners);
      const Point3 normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
      normals_.push_back(normal.norm() > 0 ? Point3(normal.normalized()) : Point3::Zero());
      sourceFaces_.push_back(tri.property(source.face, face));
      area_ += normal.norm() / 2;
    }
    for (const auto edge : tri.edges()) {
      if (tri.status(edge).feature()) {
        segments_.push_back({toPoint(tri.point(edge.v0())), toPoint(tri.point(edge.v1()))});
      }
    }
    build(triangleTree_, triangles_.size(), [&](size_t i) {
      Box box(triangles_[i][0]);
      box.extend(triangles_[i][1]).extend(triangles_[i][2]);
      return box;
    });
    build(segmentTree_, segments_.size(), [&](size_t i) {
      Box box(segments_[i][0]);
      return box.extend(segments_[i][1]);
    });
  }

  [[nodiscard]] double area() const { return area_; }

  struct Nearest {
    Point3 point = Point3::Zero();
    int triangle = -1;
    double distance2 = std::numeric_limits<double>::infinity();
  };

  // The nearest point of a triangle that faces the same side as `normal`
  // (any triangle when `normal` is zero): a thin part's other side is near
  // but is not where a vertex belongs.
  [[nodiscard]] Nearest nearestOnSurface(const Point3& p, const Point3& normal) const {
    NearestMinimizer<true> minimizer{*this, p, normal, {}};
    if (!triangles_.empty()) Eigen::BVMinimize(triangleTree_, minimizer);
    return minimizer.best;
  }

  [[nodiscard]] Nearest nearestOnFeature(const Point3& p) const {
    NearestMinimizer<false> minimizer{*this, p, Point3::Zero(), {}};
    if (!segments_.empty()) Eigen::BVMinimize(segmentTree_, minimizer);
    return minimizer.best;
  }

  [[nodiscard]] int sourceFace(int triangle) const { return triangle < 0 ? -1 : sourceFaces_[triangle]; }

 private:
  using Tree = Eigen::KdBVH<double, 3, int>;

  // A hierarchy of `count` objects numbered 0..count-1 (a lone object
  // twice: the tree needs two to have a root).
  template <class BoxOf>
  static void build(Tree& tree, size_t count, BoxOf boxOf) {
    std::vector<int> objects;
    std::vector<Box> boxes;
    for (size_t i = 0; i < count; ++i) {
      objects.push_back(static_cast<int>(i));
      boxes.push_back(boxOf(i));
    }
    if (count == 1) {
      objects.push_back(0);
      boxes.push_back(boxes.front());
    }
    if (!objects.empty()) tree.init(objects.begin(), objects.end(), boxes.begin(), boxes.end());
  }

  template <bool OnTriangles>
  struct NearestMinimizer {
    using Scalar = double;
    const ReferenceSurface& surface;
    Point3 p, normal;
    Nearest best;
    double minimumOnVolume(const Box& box) const { return box.squaredExteriorDistance(p); }
    double minimumOnObject(int i) {
      Point3 q;
      if constexpr (OnTriangles) {
        if (surface.normals_[i].dot(normal) < 0) return std::numeric_limits<double>::infinity();
        const auto& t = surface.triangles_[i];
        q = closestOnTriangle(p, t[0], t[1], t[2]);
      } else {
        q = closestOnSegment(p, surface.segments_[i][0], surface.segments_[i][1]);
      }
      const double d2 = (q - p).squaredNorm();
      if (d2 < best.distance2) best = {q, i, d2};
      return d2;
    }
  };

  std::vector<std::array<Point3, 3>> triangles_;
  std::vector<Point3> normals_;
  std::vector<int> sourceFaces_;
  std::vector<std::array<Point3, 2>> segments_;
  Tree triangleTree_, segmentTree_;
  double area_ = 0;
};

}  // namespace rotafab::geometry::projection
