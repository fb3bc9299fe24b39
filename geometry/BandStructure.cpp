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

void say(const BandOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

}  // namespace

BandStructure buildBandStructure(const PolygonMesh& mesh, const BandOptions& options) {
  if (!(options.fastener > 0)) throw std::invalid_argument("--fastener: the hole diameter must be positive");
  const RotationSystem rs = RotationSystem::fromMesh(mesh);
  // Faces as a user finds them in the file; a face capping a hole (--holes fill) has no number there.
  const auto faceName = [&](int f) {
    return mesh.sourceFaceIndex(f) >= 0 ? fmt::format("face {}", mesh.sourceFaceIndex(f))
                                        : std::string("the face filling a hole");
  };
  say(options, fmt::format("band decomposition of {} faces", mesh.faceCount()));
  const BandDecomposition decomposition = bandDecomposition(mesh, rs, options.tension);
  const std::vector<EdgeBand> bands = developableBands(rs, decomposition, options.samples);
  std::vector<FlatPanel> flat;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    try {
      flat.push_back(unfoldPanel(rs, decomposition, bands, f));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(fmt::format("{}: {}", faceName(f), error.what()));
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
  // A panel that would overlap itself (V.4) is split: one band at a time,
  // the later of two that overlap, is cut off with a tab, until none do.
  // A piece crossing itself cannot be mended so.
  int split = 0;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    for (auto overlaps = overlappingPieces(flat[f]); !overlaps.empty(); overlaps = overlappingPieces(flat[f])) {
      const auto [i, j] = overlaps.front();
      const auto where = [&] { return fmt::format("panel {} ({})", order.panelOfFace[f] + 1, faceName(f)); };
      if (j < 0) {
        throw std::invalid_argument(fmt::format(
            "{}: its vertex band crosses itself when laid flat (the face is far from planar); split the face in "
            "the mesh",
            where()));
      }
      if (i == j) {
        throw std::invalid_argument(
            fmt::format("{}: the band of {} overlaps itself when laid flat", where(), edgeName(flat[f].bands[j].edge)));
      }
      // The later band of the two, or else the earlier one: the first whose
      // tab fits, its hole clear of the piece's and the panel's outlines and
      // of the panel's other tabs.
      std::string why;
      const auto cutOff = [&](int index) {
        FlatPanel trial = flat[f];
        try {
          detachBand(trial, index, 2 * kClearance * options.fastener);
        } catch (const std::invalid_argument& error) {
          why = error.what();
          return false;
        }
        const FlatBand& cut = trial.bands[index];
        // The tab is exactly twice the clearance deep, so its hole is at the
        // clearance from the fold: allow for rounding (1e-9 in).
        const double clearance = kClearance * options.fastener - 1e-9;
        bool clear = distanceToOutline(cut.pieceOutline, cut.tab) >= clearance &&
                     insidePolygon(trial.outline, cut.tab) && distanceToOutline(trial.outline, cut.tab) >= clearance;
        for (const FlatBand& other : trial.bands) {
          if (&other != &cut && other.detached && (other.tab - cut.tab).norm() < clearance + options.fastener) {
            clear = false;
          }
        }
        if (!clear) {
          why = "the tab's hole would not keep its clearance";
          return false;
        }
        flat[f] = std::move(trial);
        return true;
      };
      if (!cutOff(j) && (i < 0 || !cutOff(i))) {
        throw std::invalid_argument(fmt::format(
            "{} would overlap itself when unfolded, and the band of {} cannot be cut off: {}; a larger --size "
            "or a smaller --fastener makes room",
            where(), edgeName(flat[f].bands[j].edge), why));
      }
      ++split;
    }
  }
  if (split > 0) {
    say(options, fmt::format("{} band{} cut off {} panel{} that would overlap themselves, each fastened back by a tab",
                             split, split == 1 ? "" : "s", split == 1 ? "a" : "the", split == 1 ? "" : "s"));
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
  result.fasteners = split;  // the tabs'
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
    // The panel's holes (a detached band's go on its piece; its tab's
    // fastener on both), and the pieces themselves.
    std::vector<Circle> circles;
    std::vector<std::vector<Circle>> pieceCircles;
    for (const FlatBand& copy : fp.bands) {
      const EdgeBand& band = bands[copy.edge];
      PanelPiece* piece = nullptr;
      if (copy.detached) {
        panel.pieces.push_back({fmt::format("{}{}", panel.id, static_cast<char>('a' + panel.pieces.size() % 26)),
                                edgeNumber[copy.edge],
                                copy.pieceOutline,
                                {},
                                {},
                                0.0});
        piece = &panel.pieces.back();
        pieceCircles.emplace_back();
      }
      auto& holesHere = piece ? piece->holes : panel.holes;
      auto& circlesHere = piece ? pieceCircles.back() : circles;
      for (const BandPoint& hole : holes[copy.edge].holes) {
        holesHere.push_back({edgeNumber[copy.edge], hole.onPanel(copy), options.fastener});
        circlesHere.push_back({holesHere.back().xy, options.fastener / 2});
      }
      if (piece) {
        piece->holes.push_back({0, copy.tab, options.fastener});
        pieceCircles.back().push_back({copy.tab, options.fastener / 2});
        panel.holes.push_back({0, copy.tab, options.fastener});
        circles.push_back({copy.tab, options.fastener / 2});
      }
      double bandArea = 0;
      for (const auto& t : band.triangles()) {
        panel.surface.push_back({band.point(t[0]), band.point(t[1]), band.point(t[2])});
        bandArea += polygonArea3(panel.surface.back());
      }
      (piece ? piece->area : panel.area) += bandArea;
      panel.neighbors.push_back(order.panelOfFace[copy.fromA ? band.faceB : band.faceA] + 1);
      panel.edges.push_back(edgeNumber[copy.edge]);
    }
    // Labels: each band's edge number near its holes, reading out from the
    // vertex band (on a piece: and the piece's name on its tab); then the
    // panel number on the vertex band.
    std::vector<TextBox> taken;
    size_t pieceIndex = 0;
    for (const FlatBand& copy : fp.bands) {
      PanelPiece* piece = copy.detached ? &panel.pieces[pieceIndex] : nullptr;
      const std::vector<Circle>& circlesHere = piece ? pieceCircles[pieceIndex] : circles;
      std::vector<TextBox> pieceTaken;
      std::vector<TextBox>& takenHere = piece ? pieceTaken : taken;
      auto& labelsHere = piece ? piece->labels : panel.labels;
      const auto& outlineHere = piece ? copy.pieceOutline : fp.outline;
      if (piece) ++pieceIndex;
      const double near = copy.fromA ? 0.0 : 1.0, far = 1.0 - near;
      const Point2 out = copy.at(far, 0.5) - copy.at(near, 0.5);
      Point2 holesAt = Point2::Zero();
      for (const BandPoint& hole : holes[copy.edge].holes) holesAt += hole.onPanel(copy);
      holesAt /= std::max<double>(1, static_cast<double>(holes[copy.edge].holes.size()));
      std::vector<Point2> candidates;
      for (double s = 0.1; s <= 0.901; s += 0.1) {
        for (double t = 0.2; t <= 0.801; t += 0.1) candidates.push_back(copy.at(s, t));
      }
      std::stable_sort(candidates.begin(), candidates.end(), [&](const Point2& a, const Point2& b) {
        return (a - holesAt).squaredNorm() < (b - holesAt).squaredNorm();
      });
      const std::string label = std::to_string(edgeNumber[copy.edge]);
      if (const auto box = fitText(font, labelText(label), std::atan2(out.y(), out.x()), copy.outline, outlineHere,
                                   circlesHere, takenHere, candidates)) {
        takenHere.push_back(*box);
        labelsHere.push_back({labelText(label), edgeNumber[copy.edge], "edge", *box,
                              labelStrokes(font, label, box->origin, box->height, box->angle)});
      } else {
        unfitted.push_back(fmt::format("edge {} on panel {}", label, panel.id));
      }
      if (piece) {
        // The piece's name on its tab, along the side it is fastened to.
        std::vector<Point2> onTab;
        for (double u = 0.2; u <= 0.801; u += 0.15) {
          for (double v = 0.2; v <= 0.801; v += 0.3) {
            const auto& t = copy.tabOutline;
            onTab.push_back((1 - v) * ((1 - u) * t[0] + u * t[1]) + v * ((1 - u) * t[3] + u * t[2]));
          }
        }
        const Point2 side = copy.tabOutline[1] - copy.tabOutline[0];
        if (const auto box = fitText(font, piece->name, std::atan2(side.y(), side.x()), copy.tabOutline,
                                     copy.pieceOutline, circlesHere, takenHere, onTab)) {
          piece->labels.push_back(
              {piece->name, 0, "piece", *box, font.strokes(piece->name, box->origin, box->height, box->angle)});
        } else {
          unfitted.push_back(fmt::format("piece {}", piece->name));
        }
      }
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
