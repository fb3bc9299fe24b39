#include "geometry/BandStructure.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <thread>

#include "geometry/BandDecomposition.h"
#include "geometry/DevelopableBands.h"
#include "geometry/FastenerHoles.h"
#include "geometry/FloodFill.h"
#include "geometry/PanelUnfolding.h"

namespace rotafab::geometry {

double constructionScale(const PolygonMesh& mesh, std::optional<double> size, std::optional<double> scale) {
  if (scale) return *scale;
  if (size) {
    Point3 low = mesh.positions.front(), high = mesh.positions.front();
    for (const Point3& p : mesh.positions) low = low.cwiseMin(p), high = high.cwiseMax(p);
    const double largest = (high - low).maxCoeff();
    if (!(largest > 0)) throw std::invalid_argument("--size: the mesh has no extent to scale");
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
  return 2.0 / (total / static_cast<double>(edges.size()));
}

namespace {

double polygonArea3(const std::vector<Point3>& polygon) {
  Point3 sum = Point3::Zero();
  for (size_t i = 0; i < polygon.size(); ++i) sum += polygon[i].cross(polygon[(i + 1) % polygon.size()]);
  return sum.norm() / 2;
}

// The point (s, t) of a flat band copy: s from its first face's side (0) to
// the second's (1), t from rail U (0) to rail V (1).
Point2 flatPoint(const FlatBand& copy, int segments, double s, double t) {
  const double x = s * segments;
  const int i = std::min(static_cast<int>(x), segments - 1);
  const double along = x - i;
  const Point2 u = (1 - along) * copy.points[i] + along * copy.points[i + 1];
  const Point2 v = (1 - along) * copy.points[segments + 1 + i] + along * copy.points[segments + 2 + i];
  return (1 - t) * u + t * v;
}

void say(const BandOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

}  // namespace

BandStructure buildBandStructure(const PolygonMesh& mesh, const BandOptions& options) {
  if (!(options.fastener > 0)) throw std::invalid_argument("--fastener: the hole diameter must be positive");
  const RotationSystem rs = RotationSystem::fromMesh(mesh);
  say(options, fmt::format("band decomposition of {} faces", mesh.faceCount()));
  const BandDecomposition decomposition = bandDecomposition(mesh, rs, options.tension);
  const std::vector<EdgeBand> bands = developableBands(rs, decomposition, options.samples);
  std::vector<FlatPanel> flat;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    try {
      flat.push_back(unfoldPanel(rs, decomposition, bands, f));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(fmt::format("face {}: {}", mesh.sourceFaceIndex(f), error.what()));
    }
  }

  int start = -1;
  if (options.start) {
    for (int f = 0; f < mesh.faceCount() && start < 0; ++f) {
      if (mesh.sourceFaceIndex(f) == *options.start) start = f;
    }
    if (start < 0) {
      throw std::invalid_argument(fmt::format(
          "--start {}: the mesh has no such face (faces are numbered from 0 as in the file)", *options.start));
    }
  } else {
    start = lowestFace(mesh, options.up);
  }
  const FloodFillOrder order = floodFill(mesh, rs, start, options.up);

  // Edges as a user finds them in the file: by their two vertices.
  const auto edgeName = [&](int e) {
    return fmt::format("the edge between vertices {} and {}", mesh.sourceVertexIndex(rs.origin(2 * e)),
                       mesh.sourceVertexIndex(rs.target(2 * e)));
  };
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto overlaps = overlappingPieces(flat[f]);
    if (!overlaps.empty()) {
      const auto [i, j] = overlaps.front();
      const int piece = j >= 0 ? j : i;
      throw std::invalid_argument(fmt::format(
          "panel {} (face {}) would overlap itself when unfolded ({}); splitting such panels is not supported "
          "yet: try another --tension",
          order.panelOfFace[f] + 1, mesh.sourceFaceIndex(f),
          piece < 0 ? std::string("its vertex band crosses itself")
                    : "the band of " + edgeName(flat[f].bands[piece].edge)));
    }
  }

  // Edge numbers in the order the flood fill meets the edges, so that the
  // numbers a builder looks for next are close to the ones in hand.
  BandStructure result;
  std::vector<int> edgeNumber(rs.edgeCount(), 0);
  for (int face : order.faceOfPanel) {
    Dart d = rs.faceDart(face);
    for (size_t side = 0; side < mesh.faces[face].size(); ++side, d = rs.faceNext(d)) {
      const int e = RotationSystem::edgeOf(d);
      if (!rs.isBoundaryEdge(e) && edgeNumber[e] == 0) edgeNumber[e] = ++result.interiorEdges;
    }
  }

  say(options, fmt::format("fastener holes on {} bands", result.interiorEdges));
  const std::vector<BandHoles> holes = placeFastenerHoles(bands, flat, options.fastener, edgeName);
  int narrow = 0, narrowest = -1;
  for (const BandHoles& h : holes) {
    result.fasteners += static_cast<int>(h.holes.size());
    if (h.edge < 0 || h.clearance >= kClearance) continue;
    ++narrow;
    if (narrowest < 0 || h.clearance < holes[narrowest].clearance) narrowest = h.edge;
  }
  if (narrow > 0) {
    result.warnings.push_back(fmt::format(
        "{} band{} too narrow for a {:.3f} in hole {} diameters from its outlines: one hole each, down to {:.2f} "
        "diameters (edge {}); a larger --size or a smaller --fastener gives them the full clearance",
        narrow, narrow == 1 ? " is" : "s are", options.fastener, kClearance, holes[narrowest].clearance,
        edgeNumber[narrowest]));
  }

  say(options, fmt::format("labels on {} panels", mesh.faceCount()));
  const HersheyFont& font = HersheyFont::simplex();
  // Each panel on its own, so the panels are shared out among the cores.
  result.panels.resize(mesh.faceCount());
  std::vector<std::vector<std::string>> unfittedOf(mesh.faceCount());  // labels too large even at the smallest height
  const auto makePanel = [&](int number) {
    std::vector<std::string>& unfitted = unfittedOf[number];
    const int f = order.faceOfPanel[number];
    const FlatPanel& fp = flat[f];
    Panel panel;
    panel.id = number + 1;
    panel.face = mesh.sourceFaceIndex(f);
    panel.outline = fp.outline;
    const VertexBand& vb = decomposition.vertexBands[f];
    panel.area = polygonArea3(vb.corners);
    panel.surface.push_back(vb.corners);
    std::vector<Circle> circles;
    for (const FlatBand& copy : fp.bands) {
      const EdgeBand& band = bands[copy.edge];
      for (const BandPoint& hole : holes[copy.edge].holes) {
        panel.holes.push_back({edgeNumber[copy.edge], hole.onPanel(copy), options.fastener});
        circles.push_back({panel.holes.back().xy, options.fastener / 2});
      }
      for (const auto& t : band.triangles()) {
        panel.surface.push_back({band.point(t[0]), band.point(t[1]), band.point(t[2])});
        panel.area += polygonArea3(panel.surface.back());
      }
      panel.neighbors.push_back(order.panelOfFace[copy.fromA ? band.faceB : band.faceA] + 1);
      panel.edges.push_back(edgeNumber[copy.edge]);
    }
    // Labels: each band's edge number near its holes, reading out from the
    // vertex band; then the panel number on the vertex band.
    std::vector<TextBox> taken;
    for (const FlatBand& copy : fp.bands) {
      const EdgeBand& band = bands[copy.edge];
      const int k = band.segments();
      const double near = copy.fromA ? 0.0 : 1.0, far = 1.0 - near;
      const Point2 out = flatPoint(copy, k, far, 0.5) - flatPoint(copy, k, near, 0.5);
      Point2 holesAt = Point2::Zero();
      for (const BandPoint& hole : holes[copy.edge].holes) holesAt += hole.onPanel(copy);
      holesAt /= std::max<double>(1, static_cast<double>(holes[copy.edge].holes.size()));
      std::vector<Point2> candidates;
      for (double s = 0.1; s <= 0.901; s += 0.1) {
        for (double t = 0.2; t <= 0.801; t += 0.1) candidates.push_back(flatPoint(copy, k, s, t));
      }
      std::stable_sort(candidates.begin(), candidates.end(), [&](const Point2& a, const Point2& b) {
        return (a - holesAt).squaredNorm() < (b - holesAt).squaredNorm();
      });
      const std::string label = std::to_string(edgeNumber[copy.edge]);
      const auto box = fitText(font, labelText(label), std::atan2(out.y(), out.x()), copy.outline, fp.outline, circles,
                               taken, candidates);
      if (!box) {
        unfitted.push_back(fmt::format("edge {} on panel {}", label, panel.id));
        continue;
      }
      taken.push_back(*box);
      panel.labels.push_back({labelText(label), edgeNumber[copy.edge], "edge", *box,
                              labelStrokes(font, label, box->origin, box->height, box->angle)});
    }
    {
      Point2 centre = Point2::Zero();
      for (const Point2& p : fp.vertexBand) centre += p;
      centre /= static_cast<double>(fp.vertexBand.size());
      double reach = 0;
      for (const Point2& p : fp.vertexBand) reach = std::max(reach, (p - centre).norm());
      std::vector<Point2> candidates;
      for (int i = -5; i <= 5; ++i) {
        for (int j = -5; j <= 5; ++j) candidates.push_back(centre + Point2(i, j) * (reach / 5));
      }
      std::stable_sort(candidates.begin(), candidates.end(), [&](const Point2& a, const Point2& b) {
        return (a - centre).squaredNorm() < (b - centre).squaredNorm();
      });
      const std::string label = std::to_string(panel.id);
      if (const auto box =
              fitText(font, labelText(label), 0.0, fp.vertexBand, fp.outline, circles, taken, candidates)) {
        panel.labels.push_back(
            {labelText(label), 0, "panel", *box, labelStrokes(font, label, box->origin, box->height, box->angle)});
      } else {
        unfitted.push_back(fmt::format("panel number {}", panel.id));
      }
    }
    if (options.scoreFolds) {
      for (size_t side = 0; side < fp.bandOfSide.size(); ++side) {
        if (fp.bandOfSide[side] < 0) continue;
        panel.scores.push_back({fp.vertexBand[side], fp.vertexBand[(side + 1) % fp.vertexBand.size()]});
      }
    }
    result.panels[number] = std::move(panel);
  };
  const int workers = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, 16);
  std::vector<std::thread> threads;
  std::vector<std::exception_ptr> errors(workers);
  for (int w = 0; w < workers; ++w) {
    threads.emplace_back([&, w] {
      try {
        for (int number = w; number < mesh.faceCount(); number += workers) makePanel(number);
      } catch (...) {
        errors[w] = std::current_exception();
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  std::vector<std::string> unfitted;
  for (auto& some : unfittedOf) unfitted.insert(unfitted.end(), some.begin(), some.end());
  if (!unfitted.empty()) {
    std::string some;
    for (size_t i = 0; i < unfitted.size() && i < 3; ++i) some += (i ? ", " : "") + unfitted[i];
    result.warnings.push_back(fmt::format("{} label{} not etched, too large for {} band even at {} in: {}{}",
                                          unfitted.size(), unfitted.size() == 1 ? " is" : "s are",
                                          unfitted.size() == 1 ? "its" : "their", kSmallestLabel, some,
                                          unfitted.size() > 3 ? ", ..." : ""));
  }
  return result;
}

}  // namespace rotafab::geometry
