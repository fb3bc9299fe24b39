#include "geometry/Remeshing.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include "geometry/MeshMending.h"
#include "geometry/SurfaceProjection.h"
#include "geometry/TriangleMeshes.h"

namespace rotafab::geometry {
namespace {

using projection::closestOnTriangle;
using projection::ReferenceSurface;
using triangles::toOpenMesh;
using triangles::toPoint;
using triangles::TriMesh;

// An edge whose faces turn by more than this is a crease, kept.
constexpr double kCreaseDegrees = 60.0;
// No collapse or flip turns a face by more than this (the cosine).
constexpr double kLeastNormalCosine = 0.5;
// A tip: this much curvature (angle deficit, radians) within half the
// length of a vertex (a cone of half-angle 30 degrees has pi at its tip).
constexpr double kTipDeficit = std::numbers::pi / 3;
// A vertex whose faces turn from its normal by more than this is not relaxed.
constexpr double kRidgeDegrees = 50.0;
// A ridge vertex whose faces' normals spread this much in every direction
// (the least eigenvalue of their scatter over the largest) is a tip.
constexpr double kTipSpread = 0.1;
// A face of less than this share of the median's area is a sliver.
constexpr double kSliverShare = 0.3;
// ... and may move the surface by this share of the length to go.
constexpr double kMostSliverMove = 0.5;
// Features closer than this share of the length are merged.
constexpr double kFinestFeature = 0.5;
// A collapse may move the surface by at most this share of the length.
constexpr double kMostCollapseMove = 0.2;
// The rounds of Botsch and Kobbelt's five steps at the first length, and at
// each length corrected from the count.
constexpr int kFirstIterations = 10;
constexpr int kCorrectionIterations = 4;
constexpr int kCorrections = 6;
// The count aimed at by the length: within this share of the faces asked
// (adjustCount() does the rest, and then evens the mesh this many times).
constexpr double kCountTolerance = 0.02;
constexpr int kCountIterations = 3;

// Whether the feature line through `vertex` (on two feature edges) turns
// there by more than kCreaseDegrees: a corner of the boundary or of a crease.
bool turnsSharply(const TriMesh& tri, TriMesh::VertexHandle vertex) {
  std::vector<Point3> directions;
  for (const auto out : tri.voh_range(vertex)) {
    if (tri.status(out.edge()).feature()) {
      directions.push_back((toPoint(tri.point(out.to())) - toPoint(tri.point(vertex))).normalized());
    }
  }
  if (directions.size() != 2) return false;
  // Straight on: the two directions opposed.
  return -directions[0].dot(directions[1]) < std::cos(kCreaseDegrees * std::numbers::pi / 180);
}

// Marks the features of `tri`: boundary edges, and creases (kCreaseDegrees)
// that are part of a closed line or of a line between corners; a crease
// that ends in the smooth surface (one edge of a scan's noise, or a fold
// that fades out) is dropped, for its loose end could never move. A vertex
// on two feature edges is a feature (it moves along them), on one or three
// or more a corner (locked). Returns the creases kept.
int markFeatures(TriMesh& tri) {
  for (const auto edge : tri.edges()) {
    tri.status(edge).set_feature(tri.is_boundary(edge) || triangles::dihedralDegrees(tri, edge) > kCreaseDegrees);
  }
  const auto featureDegree = [&](TriMesh::VertexHandle vertex) {
    int degree = 0;
    for (const auto edge : tri.ve_range(vertex)) degree += tri.status(edge).feature() ? 1 : 0;
    return degree;
  };
  // Peel loose ends, one edge at a time, until none is left.
  std::vector<TriMesh::VertexHandle> loose;
  for (const auto vertex : tri.vertices()) {
    if (featureDegree(vertex) == 1) loose.push_back(vertex);
  }
  while (!loose.empty()) {
    const auto vertex = loose.back();
    loose.pop_back();
    if (featureDegree(vertex) != 1) continue;
    for (const auto edge : tri.ve_range(vertex)) {
      if (!tri.status(edge).feature() || tri.is_boundary(edge)) continue;
      tri.status(edge).set_feature(false);
      for (const auto end : {edge.v0(), edge.v1()}) {
        if (end != vertex && featureDegree(end) == 1) loose.push_back(end);
      }
    }
  }
  int creases = 0;
  for (const auto edge : tri.edges()) creases += tri.status(edge).feature() && !tri.is_boundary(edge) ? 1 : 0;
  for (const auto vertex : tri.vertices()) {
    const int degree = featureDegree(vertex);
    tri.status(vertex).set_feature(degree > 0);
    tri.status(vertex).set_locked(degree > 0 && (degree != 2 || turnsSharply(tri, vertex)));
  }
  return creases;
}

// The angle deficit at `vertex` (2 pi less the angles of its faces there):
// the Gaussian curvature gathered at it; 0 on the boundary.
double angleDeficit(const TriMesh& tri, TriMesh::VertexHandle vertex) {
  if (tri.is_boundary(vertex)) return 0;
  double angles = 0;
  const Point3 p = toPoint(tri.point(vertex));
  for (const auto out : tri.voh_range(vertex)) {
    const Point3 a = toPoint(tri.point(out.to())) - p;
    const Point3 b = toPoint(tri.point(tri.to_vertex_handle(tri.next_halfedge_handle(out)))) - p;
    if (tri.is_boundary(out)) continue;
    angles += std::atan2(a.cross(b).norm(), a.dot(b));
  }
  return 2 * std::numbers::pi - angles;
}

// Locks the tips of `tri` (an ear's, a finger's): where the curvature
// gathered within `radius` of a vertex exceeds kTipDeficit, the vertex of
// most deficit there, one per 2 `radius`. Relaxed toward its neighbours, a
// tip's vertex slides down its sides, and projected it stays there; locked,
// it stays the tip. Returns the tips locked.
int lockTips(TriMesh& tri, double radius) {
  std::vector<double> deficit(tri.n_vertices());
  for (const auto vertex : tri.vertices()) deficit[vertex.idx()] = angleDeficit(tri, vertex);
  // The vertices within `reach` of `from` along the edges, and `from`.
  const auto near = [&](TriMesh::VertexHandle from, double reach) {
    std::vector<TriMesh::VertexHandle> found{from}, queue{from};
    std::vector<char> seen(tri.n_vertices(), 0);
    seen[from.idx()] = 1;
    const Point3 centre = toPoint(tri.point(from));
    while (!queue.empty()) {
      const auto vertex = queue.back();
      queue.pop_back();
      for (const auto next : tri.vv_range(vertex)) {
        if (seen[next.idx()] || (toPoint(tri.point(next)) - centre).norm() > reach) continue;
        seen[next.idx()] = 1;
        found.push_back(next);
        queue.push_back(next);
      }
    }
    return found;
  };
  std::vector<std::pair<double, TriMesh::VertexHandle>> candidates;
  for (const auto vertex : tri.vertices()) {
    if (tri.status(vertex).feature() || !(deficit[vertex.idx()] > 0)) continue;
    double gathered = 0;
    for (const auto other : near(vertex, radius)) gathered += deficit[other.idx()];
    if (gathered > kTipDeficit) candidates.emplace_back(deficit[vertex.idx()], vertex);
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Point3> tips, corners;
  for (const auto vertex : tri.vertices()) {
    if (tri.status(vertex).locked()) corners.push_back(toPoint(tri.point(vertex)));
  }
  for (const auto& [gathered, vertex] : candidates) {
    const Point3 p = toPoint(tri.point(vertex));
    const auto near = [&](const Point3& other) { return (other - p).norm() < 2 * radius; };
    if (std::any_of(tips.begin(), tips.end(), near) || std::any_of(corners.begin(), corners.end(), near)) continue;
    tips.push_back(p);
    tri.status(vertex).set_locked(true);
  }
  return static_cast<int>(tips.size());
}

// Botsch and Kobbelt's remeshing loop on `tri`, whose features are marked,
// projecting onto `reference`.
class IsotropicRemesher {
 public:
  IsotropicRemesher(TriMesh& tri, const ReferenceSurface& reference, const triangles::SourceNumbers& source)
      : tri_(tri), reference_(reference), source_(source) {}

  // The count made `faces` (give or take one): the longest edges split, or
  // the shortest collapsed, one at a time, then the valences and positions
  // evened again without splits or collapses. The lengths' thresholds alone
  // leave the count wherever no edge crosses them.
  void adjustCount(size_t faces, double target) {
    std::vector<std::pair<double, int>> byLength;
    for (const auto edge : tri_.edges()) byLength.emplace_back(length(edge), edge.idx());
    if (tri_.n_faces() < faces) {
      std::sort(byLength.begin(), byLength.end(), std::greater<>());
      for (const auto& [edgeLength, index] : byLength) {
        if (tri_.n_faces() + 1 >= faces) break;
        splitEdge(OpenMesh::SmartEdgeHandle(index, &tri_));
      }
    } else {
      std::sort(byLength.begin(), byLength.end());
      // (Faces deleted stay in n_faces() until the garbage collection.)
      size_t live = tri_.n_faces();
      for (const auto& [edgeLength, index] : byLength) {
        if (live <= faces + 1) break;
        const OpenMesh::SmartEdgeHandle edge(index, &tri_);
        if (tri_.status(edge).deleted()) continue;
        for (const auto halfedge : {edge.h0(), edge.h1()}) {
          if (mayCollapse(halfedge, 2 * target, target)) {
            live -= tri_.is_boundary(edge) ? 1 : 2;
            collapseKeepingFeatures(halfedge);
            break;
          }
        }
      }
      tri_.garbage_collection();
    }
    for (int i = 0; i < kCountIterations; ++i) {
      equalizeValences();
      relaxTangentially();
      projectOntoSurface();
    }
  }

  // The last slivers (a face of less than kSliverShare of the median's
  // area, where features or tips kept vertices from evening out): an edge
  // of it collapsed, the shortest first, or else its longest flipped.
  void removeSlivers(double target) {
    std::vector<double> areas;
    for (const auto face : tri_.faces()) areas.push_back(faceArea(face));
    if (areas.empty()) return;
    std::nth_element(areas.begin(), areas.begin() + static_cast<std::ptrdiff_t>(areas.size() / 2), areas.end());
    const double least = kSliverShare * areas[areas.size() / 2];
    // An inner vertex of three faces pinches its neighbours' edges (no
    // collapse between them keeps the link condition): gone first.
    for (const auto vertex : tri_.vertices()) {
      if (tri_.status(vertex).deleted() || tri_.is_boundary(vertex) || tri_.valence(vertex) != 3) continue;
      for (const auto out : tri_.voh_range(vertex)) {
        if (mayCollapse(out, 2 * target, target, kMostSliverMove)) {
          collapseKeepingFeatures(out);
          break;
        }
      }
    }
    for (const auto face : tri_.faces()) {
      if (tri_.status(face).deleted() || faceArea(face) >= least) continue;
      std::vector<OpenMesh::SmartEdgeHandle> sides;
      for (const auto edge : tri_.fe_range(face)) sides.push_back(edge);
      std::sort(sides.begin(), sides.end(), [&](auto a, auto b) { return length(a) < length(b); });
      bool mended = false;
      for (const auto side : sides) {
        for (const auto halfedge : {side.h0(), side.h1()}) {
          if (!mended && mayCollapse(halfedge, 2 * target, target, kMostSliverMove)) {
            collapseKeepingFeatures(halfedge);
            mended = true;
          }
        }
      }
      if (!mended && mayFlip(sides.back())) tri_.flip(sides.back());
    }
    tri_.garbage_collection();
  }

  void iterate(double length) {
    splitLongEdges(4.0 / 3.0 * length);
    collapseShortEdges(length);
    equalizeValences();
    relaxTangentially();
    projectOntoSurface();
  }

 private:
  Point3 at(TriMesh::VertexHandle vertex) const { return toPoint(tri_.point(vertex)); }

  double length(OpenMesh::SmartEdgeHandle edge) const { return (at(edge.v0()) - at(edge.v1())).norm(); }

  // `edge` split at its midpoint; the halves of a feature edge are
  // features, and so is the new vertex.
  void splitEdge(OpenMesh::SmartEdgeHandle edge) {
    const auto a = edge.v0(), b = edge.v1();
    const bool feature = tri_.status(edge).feature();
    const auto middle = tri_.split_copy(edge, toOpenMesh((at(a) + at(b)) / 2));
    tri_.property(source_.vertex, middle) = -1;
    tri_.status(middle).set_locked(false);
    tri_.status(middle).set_feature(feature);
    for (const auto out : tri_.voh_range(middle)) {
      const auto other = out.to();
      tri_.status(out.edge()).set_feature(feature && (other == a || other == b));
    }
  }

  // (1) Every edge longer than `high` split at its midpoint.
  void splitLongEdges(double high) {
    for (bool again = true; again;) {
      again = false;
      const size_t edges = tri_.n_edges();
      for (size_t i = 0; i < edges; ++i) {
        const OpenMesh::SmartEdgeHandle edge(static_cast<int>(i), &tri_);
        if (tri_.status(edge).deleted() || length(edge) <= high) continue;
        splitEdge(edge);
        again = true;
      }
    }
  }

  // Whether moving `from` to `to`'s place keeps each face about `from` (but
  // the two that vanish) turned by less than 60 degrees and of some area.
  bool keepsFacesUpright(TriMesh::HalfedgeHandle halfedge) const {
    const auto from = tri_.from_vertex_handle(halfedge), to = tri_.to_vertex_handle(halfedge);
    const Point3 target = at(to);
    for (const auto face : tri_.vf_range(from)) {
      std::array<Point3, 3> before, after;
      int i = 0;
      bool vanishes = false;
      for (const auto vertex : tri_.fv_range(face)) {
        vanishes = vanishes || vertex == to;
        before[i] = at(vertex);
        after[i++] = vertex == from ? target : at(vertex);
      }
      if (vanishes) continue;
      const Point3 n0 = (before[1] - before[0]).cross(before[2] - before[0]);
      const Point3 n1 = (after[1] - after[0]).cross(after[2] - after[0]);
      if (n1.norm() <= 1e-12 * (before[1] - before[0]).squaredNorm()) return false;
      if (n0.norm() > 0 && n0.normalized().dot(n1.normalized()) < kLeastNormalCosine) return false;
    }
    return true;
  }

  // Whether `halfedge` may collapse, `length` being the target. An edge
  // shorter than kFinestFeature of it may collapse whatever its ends: a
  // feature finer than that (two creases side by side, a cluster of
  // corners on a scan's noise) cannot be kept with even triangles.
  bool mayCollapse(TriMesh::HalfedgeHandle halfedge, double high, double length, double mostMove = kMostCollapseMove) {
    const auto from = tri_.from_vertex_handle(halfedge), to = tri_.to_vertex_handle(halfedge);
    const auto edge = tri_.edge_handle(halfedge);
    if (tri_.calc_edge_length(edge) >= kFinestFeature * length) {
      if (tri_.status(from).locked()) return false;
      // A feature vertex slides along its feature only.
      if (tri_.status(from).feature() && !tri_.status(edge).feature()) return false;
    }
    if (!tri_.is_collapse_ok(halfedge)) return false;
    const Point3 target = at(to);
    for (const auto neighbour : tri_.vv_range(from)) {
      if (neighbour != to && (at(neighbour) - target).norm() > high) return false;
    }
    return keepsFacesUpright(halfedge) && movesSurfaceLittle(halfedge, length * mostMove);
  }

  // Whether `from`'s point stays within `most` of the faces about `to` once
  // `from` is gone: a collapse may not cut off a tip (an ear's, a finger's)
  // that the projection could not bring back.
  bool movesSurfaceLittle(TriMesh::HalfedgeHandle halfedge, double most) const {
    const auto from = tri_.from_vertex_handle(halfedge), to = tri_.to_vertex_handle(halfedge);
    const Point3 p = at(from), target = at(to);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto face : tri_.vf_range(from)) {
      std::array<Point3, 3> after;
      int i = 0;
      bool vanishes = false;
      for (const auto vertex : tri_.fv_range(face)) {
        vanishes = vanishes || vertex == to;
        after[i++] = vertex == from ? target : at(vertex);
      }
      if (!vanishes) nearest = std::min(nearest, (closestOnTriangle(p, after[0], after[1], after[2]) - p).norm());
    }
    return nearest <= most;
  }

  // Collapses `halfedge`'s from-vertex into its to-vertex. Each of the two
  // triangles that vanish merges its two other edges into one, which is a
  // feature if either was.
  void collapseKeepingFeatures(TriMesh::HalfedgeHandle halfedge) {
    const auto to = tri_.to_vertex_handle(halfedge);
    std::vector<TriMesh::VertexHandle> features;
    for (const auto side : {halfedge, tri_.opposite_halfedge_handle(halfedge)}) {
      if (tri_.is_boundary(side)) continue;
      const auto next = tri_.next_halfedge_handle(side), previous = tri_.prev_halfedge_handle(side);
      if (tri_.status(tri_.edge_handle(next)).feature() || tri_.status(tri_.edge_handle(previous)).feature()) {
        features.push_back(tri_.to_vertex_handle(next));
      }
    }
    const auto from = tri_.from_vertex_handle(halfedge);
    const bool locked = tri_.status(from).locked(), feature = tri_.status(from).feature();
    tri_.collapse(halfedge);
    for (const auto other : features) {
      const auto merged = tri_.find_halfedge(to, other);
      if (merged.is_valid()) tri_.status(tri_.edge_handle(merged)).set_feature(true);
    }
    // (A corner or feature vertex collapsed into another, where a feature
    // too fine to keep is merged: what is left is the corner, or a corner
    // where its feature lines no longer pass straight through.)
    if (feature || locked) {
      int degree = 0;
      for (const auto edge : tri_.ve_range(to)) degree += tri_.status(edge).feature() ? 1 : 0;
      tri_.status(to).set_feature(tri_.status(to).feature() || feature);
      tri_.status(to).set_locked(tri_.status(to).locked() || locked || degree != 2);
    }
  }

  // (2) Every edge shorter than 4/5 `target` collapsed, one end into the
  // other, unless that makes an edge longer than 4/3 `target`.
  void collapseShortEdges(double target) {
    const double low = 4.0 / 5.0 * target, high = 4.0 / 3.0 * target;
    for (bool again = true; again;) {
      again = false;
      for (const auto edge : tri_.edges()) {
        if (tri_.status(edge).deleted() || length(edge) >= low) continue;
        for (const auto halfedge : {edge.h0(), edge.h1()}) {
          if (mayCollapse(halfedge, high, target)) {
            collapseKeepingFeatures(halfedge);
            again = true;
            break;
          }
        }
      }
      tri_.garbage_collection();
    }
  }

  int valenceDeviation(TriMesh::VertexHandle vertex, int change) const {
    const int target = tri_.is_boundary(vertex) ? 4 : 6;
    return std::abs(static_cast<int>(tri_.valence(vertex)) + change - target);
  }

  // Whether `edge` may flip: not a feature nor on the boundary, and its two
  // new faces of some area, facing the old ones' way and turned from each
  // other by less than 60 degrees.
  bool mayFlip(OpenMesh::SmartEdgeHandle edge) const {
    if (tri_.status(edge).feature() || tri_.is_boundary(edge) || !tri_.is_flip_ok(edge)) return false;
    const auto h = edge.h0(), o = edge.h1();
    const auto a = tri_.from_vertex_handle(h), b = tri_.to_vertex_handle(h);
    const auto c = tri_.to_vertex_handle(tri_.next_halfedge_handle(h));
    const auto d = tri_.to_vertex_handle(tri_.next_halfedge_handle(o));
    // The faces (a, b, c) and (b, a, d) become (a, d, c) and (d, b, c).
    const Point3 pa = at(a), pb = at(b), pc = at(c), pd = at(d);
    const Point3 old = (pb - pa).cross(pc - pa) + (pa - pb).cross(pd - pb);
    const Point3 n1 = (pd - pa).cross(pc - pa), n2 = (pb - pd).cross(pc - pd);
    const double least = 1e-12 * (pa - pb).squaredNorm();
    if (n1.norm() <= least || n2.norm() <= least) return false;
    if (n1.dot(old) <= 0 || n2.dot(old) <= 0) return false;
    return n1.normalized().dot(n2.normalized()) >= kLeastNormalCosine;
  }

  // (3) Edges flipped where that brings the valences of their four vertices
  // nearer 6 (4 on the boundary), unless a feature or a fold.
  void equalizeValences() {
    for (const auto edge : tri_.edges()) {
      if (tri_.status(edge).deleted() || tri_.status(edge).feature() || tri_.is_boundary(edge)) continue;
      const auto h = edge.h0(), o = edge.h1();
      const auto a = tri_.from_vertex_handle(h), b = tri_.to_vertex_handle(h);
      const auto c = tri_.to_vertex_handle(tri_.next_halfedge_handle(h));
      const auto d = tri_.to_vertex_handle(tri_.next_halfedge_handle(o));
      const int before =
          valenceDeviation(a, 0) + valenceDeviation(b, 0) + valenceDeviation(c, 0) + valenceDeviation(d, 0);
      const int after =
          valenceDeviation(a, -1) + valenceDeviation(b, -1) + valenceDeviation(c, 1) + valenceDeviation(d, 1);
      if (after < before && mayFlip(edge)) tri_.flip(edge);
    }
  }

  Point3 vertexNormal(TriMesh::VertexHandle vertex) const {
    Point3 normal = Point3::Zero();
    for (const auto face : tri_.vf_range(vertex)) normal += toPoint(tri_.calc_face_normal(face)) * faceArea(face);
    return normal.norm() > 0 ? Point3(normal.normalized()) : normal;
  }

  double faceArea(TriMesh::FaceHandle face) const {
    std::array<Point3, 3> p;
    int i = 0;
    for (const auto vertex : tri_.fv_range(face)) p[i++] = at(vertex);
    return (p[1] - p[0]).cross(p[2] - p[0]).norm() / 2;
  }

  // Whether a face about `vertex` turns from its `normal` by more than
  // kRidgeDegrees: the vertex is on a ridge or a tip (an ear's rim), which
  // relaxing would pull in and the projection would not restore.
  bool onARidge(TriMesh::VertexHandle vertex, const Point3& normal) const {
    const double least = std::cos(kRidgeDegrees * std::numbers::pi / 180);
    for (const auto face : tri_.vf_range(vertex)) {
      if (toPoint(tri_.calc_face_normal(face)).dot(normal) < least) return true;
    }
    return false;
  }

  bool joinedByAFeature(TriMesh::VertexHandle a, TriMesh::VertexHandle b) const {
    const auto halfedge = tri_.find_halfedge(a, b);
    return halfedge.is_valid() && tri_.status(tri_.edge_handle(halfedge)).feature();
  }

  // (4) Each vertex moved toward the area-weighted centroid of its faces,
  // within its tangent plane; a feature vertex toward the middle of its two
  // feature neighbours; corners stay.
  void relaxTangentially() {
    std::vector<std::optional<Point3>> moved(tri_.n_vertices());
    for (const auto vertex : tri_.vertices()) {
      if (tri_.status(vertex).locked()) continue;
      const Point3 p = at(vertex);
      if (tri_.status(vertex).feature()) {
        Point3 sum = Point3::Zero();
        std::vector<TriMesh::VertexHandle> along;
        for (const auto out : tri_.voh_range(vertex)) {
          if (tri_.status(out.edge()).feature()) {
            sum += at(out.to());
            along.push_back(out.to());
          }
        }
        // (Three feature vertices joined in a loop stay: each relaxed toward
        // the other two, the loop shrinks to a point, its faces to none.)
        if (along.size() == 2 && !joinedByAFeature(along[0], along[1])) moved[vertex.idx()] = (p + sum / 2) / 2;
        continue;
      }
      Point3 centroid = Point3::Zero();
      double area = 0;
      for (const auto face : tri_.vf_range(vertex)) {
        const double a = faceArea(face);
        Point3 centre = Point3::Zero();
        for (const auto corner : tri_.fv_range(face)) centre += at(corner) / 3;
        centroid += centre * a;
        area += a;
      }
      if (!(area > 0)) continue;
      centroid /= area;
      const Point3 normal = vertexNormal(vertex);
      if (onARidge(vertex, normal)) {
        // Along the ridge only: the direction its faces' normals leave out
        // (the least eigenvector of their scatter); a tip, which has none, stays.
        Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
        for (const auto face : tri_.vf_range(vertex)) {
          const Point3 n = toPoint(tri_.calc_face_normal(face));
          scatter += faceArea(face) * n * n.transpose();
        }
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
        const Eigen::Vector3d spread = solver.eigenvalues();
        if (!(spread[0] < kTipSpread * spread[2])) continue;
        const Point3 along = solver.eigenvectors().col(0);
        moved[vertex.idx()] = p + along * along.dot(centroid - p);
        continue;
      }
      moved[vertex.idx()] = centroid + normal * normal.dot(p - centroid);
    }
    for (const auto vertex : tri_.vertices()) {
      if (moved[vertex.idx()]) tri_.set_point(vertex, toOpenMesh(*moved[vertex.idx()]));
    }
  }

  // (5) Each vertex onto the input: a feature vertex onto its feature lines,
  // any other onto the nearest point of a triangle that faces its way.
  void projectOntoSurface() {
    for (const auto vertex : tri_.vertices()) {
      if (tri_.status(vertex).locked()) continue;
      const Point3 p = at(vertex);
      const ReferenceSurface::Nearest nearest = tri_.status(vertex).feature()
                                                    ? reference_.nearestOnFeature(p)
                                                    : reference_.nearestOnSurface(p, vertexNormal(vertex));
      if (nearest.triangle >= 0) tri_.set_point(vertex, toOpenMesh(nearest.point));
    }
  }

  TriMesh& tri_;
  const ReferenceSurface& reference_;
  const triangles::SourceNumbers& source_;
};

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The result's measures: its faces' smallest area over their median, and
// the farthest a vertex of either surface lies from the other (the
// result's vertices are on the input; the input's tips and rims may not be
// on the result).
void measure(TriMesh& tri, const triangles::SourceNumbers& source, const TriMesh& input,
             const ReferenceSurface& reference, Remeshing& result) {
  std::vector<double> areas;
  for (const auto face : tri.faces()) areas.push_back(tri.calc_face_area(face));
  const double middle = median(areas);
  result.smallestAreaRatio = middle > 0 ? *std::min_element(areas.begin(), areas.end()) / middle : 0;
  double farthest = 0;
  for (const auto vertex : tri.vertices()) {
    farthest = std::max(farthest, reference.nearestOnSurface(toPoint(tri.point(vertex)), Point3::Zero()).distance2);
  }
  const ReferenceSurface remeshed(tri, source);
  for (const auto vertex : input.vertices()) {
    farthest = std::max(farthest, remeshed.nearestOnSurface(toPoint(input.point(vertex)), Point3::Zero()).distance2);
  }
  result.largestMove = std::sqrt(farthest);
}

}  // namespace

Remeshing remeshEvenly(PolygonMesh& mesh, int faces, const core::WorkContext& context) {
  if (faces < 1) throw std::invalid_argument("expected a panel count of at least 1");
  Remeshing result;
  result.asked = faces;
  result.facesBefore = result.facesAfter = mesh.faceCount();
  if (std::abs(mesh.faceCount() - faces) <= kKeptAsDrawn * faces) return result;

  const triangles::QuietOpenMesh quiet;
  TriMesh input;
  triangles::SourceNumbers inputSource;
  triangles::toTriangleMesh(mesh, input, inputSource);
  result.creaseEdges = markFeatures(input);
  const ReferenceSurface reference(input, inputSource);

  // (OpenMesh's copy keeps the properties, the features and their handles.)
  TriMesh tri = input;
  const triangles::SourceNumbers& source = inputSource;

  // Equilateral triangles of side L cover sqrt(3)/4 L^2 each.
  double length = std::sqrt(4 * reference.area() / (std::sqrt(3.0) * faces));
  // (Tips at the scale of the mesh's own edges, where they are longer.)
  double edges = 0;
  for (const auto edge : tri.edges()) edges += tri.calc_edge_length(edge);
  result.tips = lockTips(tri, std::max(length, edges / static_cast<double>(tri.n_edges())) / 2);
  IsotropicRemesher remesher(tri, reference, source);
  const size_t steps = kFirstIterations + kCorrections * kCorrectionIterations;
  size_t step = 0;
  const auto iterate = [&](int times) {
    for (int i = 0; i < times; ++i) {
      context.check();
      context.report({"import", "remesh", ++step, steps});
      remesher.iterate(length);
    }
  };
  iterate(kFirstIterations);
  for (int correction = 0; correction < kCorrections; ++correction) {
    const double got = static_cast<double>(tri.n_faces());
    if (std::abs(got - faces) <= kCountTolerance * faces) break;
    length *= std::sqrt(got / faces);
    iterate(kCorrectionIterations);
  }
  remesher.adjustCount(static_cast<size_t>(faces), length);
  remesher.removeSlivers(length);
  context.report({"import", "remesh", steps, steps});

  tri.garbage_collection();
  for (const auto face : tri.faces()) {
    Point3 centre = Point3::Zero();
    for (const auto vertex : tri.fv_range(face)) centre += toPoint(tri.point(vertex)) / 3;
    const Point3 normal = toPoint(tri.calc_face_normal(face));
    tri.property(source.face, face) = reference.sourceFace(reference.nearestOnSurface(centre, normal).triangle);
  }
  for (const auto vertex : tri.vertices()) tri.property(source.vertex, vertex) = -1;
  measure(tri, source, input, reference, result);
  mesh = triangles::fromTriangleMesh(tri, source);
  // A face whose corners slid into one line along a crease (no collapse or
  // flip there kept the features) goes as the import's repair takes it away.
  const MeshRepair collinear = collapseDegenerateFaces(mesh);
  result.largestMove = std::max(result.largestMove, collinear.moved);
  mesh.sourceVertex.clear();
  result.remeshed = true;
  result.facesAfter = mesh.faceCount();
  return result;
}

}  // namespace rotafab::geometry
