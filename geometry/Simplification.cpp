#include "geometry/Simplification.h"

#include <fmt/format.h>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/McDecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModAspectRatioT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <OpenMesh/Tools/Decimater/Observer.hh>
#include <array>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <type_traits>

#include "core/Polygon2.h"
#include "geometry/BandDecomposition.h"

namespace rotafab::geometry {
namespace {

// Double precision throughout: the mesh comes in and goes out as doubles.
struct DoubleTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

// A collapse may not turn a face's normal by more than this: a larger turn
// folds the surface over (a flipped face) or bends a panel out of the shape.
constexpr double kMaxNormalTurnDegrees = 60.0;
// The turns of one collapse after another add up, and a surface can fold
// onto itself (an octahedron asked for 4 faces became four points in a
// plane, covered twice): two faces on one edge whose normals are more
// opposed than this lie back to back.
constexpr double kFoldedCosine = -0.95;
// Nor leave a triangle longer than this many times its height: a sliver has
// no room for a fastener hole at any scale the bed takes.
constexpr float kMaxAspectRatio = 8.0f;
// Collapses between reports of progress and checks of the cancel.
constexpr size_t kStepsPerReport = 256;
// Multiple choice takes a large mesh down to this many times the faces asked
// (the queue does the rest), choosing the best of this many edges a step.
constexpr size_t kQueueShare = 2;
constexpr size_t kChoices = 8;
constexpr unsigned kChoiceSeed = 1;

// Reports the collapses so far (`before` of them by an earlier decimater) and stops at a cancel.
class Progress final : public OpenMesh::Decimater::Observer {
 public:
  Progress(const core::WorkContext& context, size_t before, size_t collapses)
      : Observer(kStepsPerReport), context_(context), before_(before), collapses_(collapses) {}
  void notify(size_t step) override {
    context_.report({"import", "simplify", std::min(before_ + step, collapses_), collapses_});
  }
  [[nodiscard]] bool abort() const override { return context_.cancelled(); }

 private:
  const core::WorkContext& context_;
  size_t before_, collapses_;
};

// Collapses edges of `mesh` by `Decimater` until it has `faces` faces or no
// collapse is allowed; returns how many it made. The modules: the quadric
// error orders the collapses; a face turned too far or a sliver forbids one.
template <template <class> class Decimater>
size_t decimate(TriMesh& mesh, size_t faces, const core::WorkContext& context, size_t before, size_t collapses) {
  Decimater<TriMesh> decimater(mesh);
  typename OpenMesh::Decimater::ModQuadricT<TriMesh>::Handle quadric;
  typename OpenMesh::Decimater::ModNormalFlippingT<TriMesh>::Handle flipping;
  typename OpenMesh::Decimater::ModAspectRatioT<TriMesh>::Handle aspect;
  decimater.add(quadric);
  decimater.add(flipping);
  decimater.add(aspect);
  decimater.module(quadric).unset_max_err();
  decimater.module(flipping).set_max_normal_deviation(kMaxNormalTurnDegrees);
  decimater.module(aspect).set_aspect_ratio(kMaxAspectRatio);
  if constexpr (std::is_same_v<Decimater<TriMesh>, OpenMesh::Decimater::McDecimaterT<TriMesh>>) {
    decimater.set_samples(kChoices);
  }
  Progress progress(context, before, collapses);
  decimater.set_observer(&progress);
  decimater.initialize();
  const size_t made = decimater.decimate_to_faces(0, faces);
  decimater.set_observer(nullptr);
  context.check();
  return made;
}

// OpenMesh's streams off while it lives: a library's message is not ours to
// print. The streams are the process's, so one simplification runs at a
// time (a daemon may plan two jobs at once).
class QuietOpenMesh {
 public:
  QuietOpenMesh() : lock_(mutex()) {
    omerr().disable();
    omlog().disable();
    omout().disable();
  }
  ~QuietOpenMesh() {
    omerr().enable();
    omlog().enable();
    omout().enable();
  }
  QuietOpenMesh(const QuietOpenMesh&) = delete;
  QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex streams;
    return streams;
  }
  std::lock_guard<std::mutex> lock_;
};

Eigen::Vector2d inPlane(const Point3& p, const Point3& u, const Point3& v) { return {p.dot(u), p.dot(v)}; }

using core::turn;

}  // namespace

std::vector<std::array<int, 3>> faceTriangles(const PolygonMesh& mesh, int face) {
  const std::vector<int>& corners = mesh.faces[face];
  const size_t n = corners.size();
  std::vector<std::array<int, 3>> triangles;
  if (n == 3) return {{corners[0], corners[1], corners[2]}};
  std::vector<Point3> polygon;
  for (int v : corners) polygon.push_back(mesh.positions[v]);
  const Point3 normal = newellNormal(polygon);
  // The plane's axes, so that the polygon turns counter-clockwise in it.
  const Point3 u = normal.unitOrthogonal();
  const Point3 v = normal.cross(u);
  std::vector<Eigen::Vector2d> flat;
  for (const Point3& p : polygon) flat.push_back(inPlane(p, u, v));
  std::vector<size_t> left(n);
  for (size_t i = 0; i < n; ++i) left[i] = i;
  while (left.size() > 3) {
    bool clipped = false;
    const size_t m = left.size();
    for (size_t i = 0; i < m && !clipped; ++i) {
      const size_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
      if (turn(flat[a], flat[b], flat[c]) <= 0) continue;  // a reflex or straight corner is no ear
      bool empty = true;
      for (size_t k : left) {
        if (k == a || k == b || k == c) continue;
        if (turn(flat[a], flat[b], flat[k]) >= 0 && turn(flat[b], flat[c], flat[k]) >= 0 &&
            turn(flat[c], flat[a], flat[k]) >= 0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      triangles.push_back({corners[a], corners[b], corners[c]});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(i));
      clipped = true;
    }
    if (!clipped) break;
  }
  if (left.size() == 3) {
    triangles.push_back({corners[left[0]], corners[left[1]], corners[left[2]]});
  } else {
    // No ear: a fan over what is left, so that every corner is still used.
    for (size_t i = 1; i + 1 < left.size(); ++i) {
      triangles.push_back({corners[left[0]], corners[left[i]], corners[left[i + 1]]});
    }
  }
  return triangles;
}

namespace {

// The inner edges whose two faces lie back to back (kFoldedCosine).
size_t foldedEdges(TriMesh& mesh) {
  mesh.update_face_normals();
  size_t folded = 0;
  for (const auto edge : mesh.edges()) {
    if (mesh.is_boundary(edge)) continue;
    const auto a = mesh.face_handle(mesh.halfedge_handle(edge, 0)), b = mesh.face_handle(mesh.halfedge_handle(edge, 1));
    if (OpenMesh::dot(mesh.normal(a), mesh.normal(b)) < kFoldedCosine) ++folded;
  }
  return folded;
}

}  // namespace

Simplification simplifyMesh(PolygonMesh& mesh, int faces, const core::WorkContext& context) {
  if (faces < 1) throw std::invalid_argument("expected a panel count of at least 1");
  Simplification result;
  result.asked = faces;
  result.facesBefore = result.facesAfter = mesh.faceCount();
  if (mesh.faceCount() <= faces) return result;

  TriMesh tri;
  auto sourceVertex = OpenMesh::VPropHandleT<int>();
  auto sourceFace = OpenMesh::FPropHandleT<int>();
  tri.add_property(sourceVertex);
  tri.add_property(sourceFace);
  std::vector<TriMesh::VertexHandle> handles;
  handles.reserve(mesh.positions.size());
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const Point3& p = mesh.positions[v];
    handles.push_back(tri.add_vertex({p.x(), p.y(), p.z()}));
    tri.property(sourceVertex, handles.back()) = mesh.sourceVertexIndex(v);
  }
  // OpenMesh reports a face it cannot add on its error stream; the check of
  // the returned handle below says it in our words instead.
  const QuietOpenMesh quiet;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto triangles = faceTriangles(mesh, f);
    result.triangulated = result.triangulated || triangles.size() > 1;
    for (const auto& t : triangles) {
      const auto handle = tri.add_face(handles[t[0]], handles[t[1]], handles[t[2]]);
      if (!handle.is_valid()) {
        throw InvalidMeshError(
            fmt::format("face {}: its triangles would give an edge a third face, so the mesh cannot be simplified",
                        mesh.sourceFaceIndex(f)));
      }
      tri.property(sourceFace, handle) = mesh.sourceFaceIndex(f);
    }
  }
  if (static_cast<int>(tri.n_faces()) > faces) {
    // The boundary keeps its place: no vertex on it moves.
    for (const auto vertex : tri.vertices()) {
      if (tri.is_boundary(vertex)) tri.status(vertex).set_locked(true);
    }
    tri.update_face_normals();
    const size_t foldedBefore = foldedEdges(tri);
    // Each collapse of an inner edge takes two triangles.
    const size_t collapses = (tri.n_faces() - static_cast<size_t>(faces) + 1) / 2;
    // A large mesh goes most of the way by multiple choice (Wu and Kobbelt,
    // "Fast Mesh Decimation by Multiple-Choice Techniques", 2002: the best of
    // a few random edges each step, no priority queue), which is several
    // times quicker, and the rest of the way, where the choice matters most
    // and random picks find fewer legal collapses, by the queue.
    const size_t byChoiceTo = static_cast<size_t>(faces) * kQueueShare;
    size_t done = 0;
    if (tri.n_faces() > 2 * byChoiceTo) {
      // OpenMesh picks its edges with rand(): seeded the same every time (one
      // simplification at a time, QuietOpenMesh), the same mesh and count
      // give the same panels in every run and in a daemon's every job.
      std::srand(kChoiceSeed);
      done += decimate<OpenMesh::Decimater::McDecimaterT>(tri, byChoiceTo, context, done, collapses);
      tri.garbage_collection();
    }
    decimate<OpenMesh::Decimater::DecimaterT>(tri, static_cast<size_t>(faces), context, done, collapses);
    if (const size_t folded = foldedEdges(tri); folded > foldedBefore) {
      size_t left = 0;
      for ([[maybe_unused]] const auto face : tri.faces()) ++left;
      throw std::invalid_argument(fmt::format(
          "at {} faces the surface would fold onto itself ({} edge{} with faces back to back); ask for more", left,
          folded - foldedBefore, folded - foldedBefore == 1 ? "" : "s"));
    }
    context.check();
    tri.garbage_collection();
  }

  PolygonMesh simplified;
  simplified.positions.reserve(tri.n_vertices());
  for (const auto vertex : tri.vertices()) {
    const auto& p = tri.point(vertex);
    simplified.positions.emplace_back(p[0], p[1], p[2]);
    simplified.sourceVertex.push_back(tri.property(sourceVertex, vertex));
  }
  simplified.faces.reserve(tri.n_faces());
  for (const auto face : tri.faces()) {
    std::vector<int> corners;
    for (const auto vertex : tri.fv_range(face)) corners.push_back(vertex.idx());
    simplified.faces.push_back(std::move(corners));
    simplified.sourceFace.push_back(tri.property(sourceFace, face));
  }
  mesh = std::move(simplified);
  result.facesAfter = mesh.faceCount();
  return result;
}

}  // namespace rotafab::geometry
