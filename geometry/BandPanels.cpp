// Each band panel whole (dissertation V.3-V.5): its outline with its
// bands, their holes, the edge numbers and the panel's number, the folds to
// score. BandBuild.h declares what BandStructure.cpp calls.
#include "geometry/BandBuild.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "geometry/PanelLabels.h"

namespace rotafab::geometry::band {
namespace {

// A panel's holes drawn as circles, for the labels to keep clear of: the
// panel's own, and each piece's.
struct PanelCircles {
  std::vector<Circle> panel;
  std::vector<std::vector<Circle>> pieces;
};

// Panel `number` (from 0) of the flood fill's order: its outline, surface,
// area, holes (a detached band's go on its piece; its tab's fastener on
// both), its pieces and its joins (V.5).
Panel panelWithBands(const BandBuild& b, const std::vector<BandHoles>& holes, int number, PanelCircles& circles) {
  const double fastener = b.options.fastener;
  const int f = b.order.faceOfPanel[number];
  const FlatPanel& fp = b.flat[f];
  Panel panel;
  panel.id = number + 1;
  panel.source.face = b.mesh.sourceFaceIndex(f);
  panel.source.cap = panel.source.face < 0;
  panel.outline = fp.outline;
  const VertexBand& vb = b.decomposition.vertexBands[f];
  panel.area = polygonArea3(vb.corners);
  panel.surface.push_back(vb.corners);
  for (const FlatBand& copy : fp.bands) {
    const EdgeBand& band = b.bands[copy.edge];
    const int edge = b.edgeNumber[copy.edge];
    PanelPiece* piece = nullptr;
    if (copy.detached || copy.halved) {
      panel.pieces.push_back({fmt::format("{}{}", panel.id, static_cast<char>('a' + panel.pieces.size() % 26)),
                              edge,
                              copy.pieceOutline,
                              {},
                              {},
                              0.0,
                              copy.halved     ? PieceFastening::Band
                              : copy.tabGlued ? PieceFastening::Glue
                                              : PieceFastening::Tab});
      piece = &panel.pieces.back();
      circles.pieces.emplace_back();
    }
    for (const BandPoint& hole : holes[copy.edge].holes) {
      const Point2 at = hole.onPanel(copy);
      const bool onPiece = copy.onPiece(at);
      (onPiece ? piece->holes : panel.holes).push_back({edge, at, fastener});
      (onPiece ? circles.pieces.back() : circles.panel).push_back({at, fastener / 2});
    }
    if (copy.detached && !copy.tabGlued) {
      piece->holes.push_back({0, copy.tab, fastener});
      circles.pieces.back().push_back({copy.tab, fastener / 2});
      panel.holes.push_back({0, copy.tab, fastener});
      circles.panel.push_back({copy.tab, fastener / 2});
    }
    double bandArea = 0;
    for (const auto& t : band.triangles()) {
      panel.surface.push_back({band.point(t[0]), band.point(t[1]), band.point(t[2])});
      bandArea += polygonArea3(panel.surface.back());
    }
    // Laid flat without stretching: the far half's area is its outline's.
    const double pieceArea = copy.halved ? signedArea(copy.pieceOutline) : copy.detached ? bandArea : 0.0;
    if (piece) piece->area += pieceArea;
    panel.area += bandArea - pieceArea;
    panel.joins.push_back({b.order.panelOfFace[copy.fromA ? band.faceB : band.faceA] + 1, edge});
  }
  return panel;
}

// A piece's name etched in `box`, or, where none fitted, counted among the
// labels left out (the piece is fastened by band `edge`).
void namePiece(PanelPiece& piece, int edge, const HersheyFont& font, const std::optional<TextBox>& box,
               std::vector<Unetched>& unfitted) {
  if (!box) {
    unfitted.push_back({fmt::format("piece {}", piece.name), edge});
    return;
  }
  piece.labels.push_back(
      {piece.name, 0, LabelRole::Piece, *box, font.strokes(piece.name, box->origin, box->height, box->angle)});
}

// A detached band's piece named on its tab, along the side it is fastened to.
void namePieceOnItsTab(const FlatBand& copy, PanelPiece& piece, const HersheyFont& font,
                       const std::vector<Circle>& circles, const std::vector<TextBox>& taken,
                       std::vector<Unetched>& unfitted) {
  std::vector<Point2> onTab;
  const auto& t = copy.tabOutline;
  Point2 middle = Point2::Zero();
  for (const Point2& p : t) middle += p;
  middle /= static_cast<double>(t.size());
  for (double u = 0.2; u <= 0.801; u += 0.15) {
    for (double v = 0.2; v <= 0.801; v += 0.3) onTab.push_back((1 - v) * ((1 - u) * t[0] + u * t[1]) + v * middle);
  }
  const Point2 side = copy.tabOutline[1] - copy.tabOutline[0];
  namePiece(piece, copy.edge, font,
            fitText(font, piece.name, alongThenAcross(std::atan2(side.y(), side.x())), copy.tabOutline,
                    copy.pieceOutline, circles, taken, onTab),
            unfitted);
}

// A band cut across: the far half's name on it, reading out along the
// band (`near` to `far`), nearest its middle.
void nameFarHalf(const FlatBand& copy, double near, double far, PanelPiece& half, const HersheyFont& font,
                 const std::vector<Circle>& circles, std::vector<Unetched>& unfitted) {
  const Point2 out = copy.at(far, 0.5) - copy.at(near, 0.5);
  std::vector<Point2> onHalf;
  for (double u = 0.65; u <= 0.951; u += 0.05) {
    for (double t = 0.3; t <= 0.701; t += 0.1) onHalf.push_back(copy.at(near + (far - near) * u, t));
  }
  const Point2 middle = copy.at(near + (far - near) * 0.75, 0.5);
  std::stable_sort(onHalf.begin(), onHalf.end(), [&](const Point2& a, const Point2& b) {
    return (a - middle).squaredNorm() < (b - middle).squaredNorm();
  });
  namePiece(half, copy.edge, font,
            fitText(font, half.name, alongThenAcross(std::atan2(out.y(), out.x())), copy.pieceOutline,
                    copy.pieceOutline, circles, {}, onHalf),
            unfitted);
}

// Each band's edge number near its holes, reading out from the vertex band
// (on a piece: and the piece's name on its tab; on a band cut across, the
// far half's name on it). Returns the boxes taken on the panel; a band
// whose number fits nowhere on it goes in `onTheBody` (labelOnTheBody()).
std::vector<TextBox> labelBands(const BandBuild& b, const std::vector<BandHoles>& holes, const FlatPanel& fp,
                                const HersheyFont& font, const PanelCircles& circles, Panel& panel,
                                std::vector<const FlatBand*>& onTheBody, std::vector<Unetched>& unfitted) {
  std::vector<TextBox> taken;
  size_t pieceIndex = 0;
  for (const FlatBand& copy : fp.bands) {
    // The edge number goes where the band's near end is: on the piece of
    // a band cut off, on the panel of a band cut across.
    PanelPiece* cut = copy.detached || copy.halved ? &panel.pieces[pieceIndex] : nullptr;
    const std::vector<Circle>* cutCircles = cut ? &circles.pieces[pieceIndex] : nullptr;
    if (cut) ++pieceIndex;
    PanelPiece* piece = copy.detached ? cut : nullptr;
    const std::vector<Circle>& circlesHere = piece ? *cutCircles : circles.panel;
    std::vector<TextBox> pieceTaken;
    std::vector<TextBox>& takenHere = piece ? pieceTaken : taken;
    auto& labelsHere = piece ? piece->labels : panel.labels;
    const auto& outlineHere = piece ? copy.pieceOutline : fp.outline;
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
    const int edge = b.edgeNumber[copy.edge];
    const std::string label = std::to_string(edge);
    if (const auto box = fitText(font, labelText(label), alongThenAcross(std::atan2(out.y(), out.x())), copy.outline,
                                 outlineHere, circlesHere, takenHere, candidates)) {
      takenHere.push_back(*box);
      labelsHere.push_back({labelText(label), edge, LabelRole::Edge, *box,
                            labelStrokes(font, label, box->origin, box->height, box->angle)});
    } else if (!piece) {
      onTheBody.push_back(&copy);  // (tried on the vertex band once the panel's number is there)
    } else {
      unfitted.push_back({fmt::format("edge {} on panel {}", label, panel.id), copy.edge});
    }
    if (piece) {
      namePieceOnItsTab(copy, *piece, font, circlesHere, takenHere, unfitted);
    } else if (cut) {
      nameFarHalf(copy, near, far, *cut, font, *cutCircles, unfitted);
    }
  }
  return taken;
}

Point2 vertexBandCentre(const FlatPanel& fp) {
  Point2 centre = Point2::Zero();
  for (const Point2& p : fp.vertexBand) centre += p;
  return centre / static_cast<double>(fp.vertexBand.size());
}

// Points over the vertex band, nearest `near` first, for a label's centre.
std::vector<Point2> vertexBandCandidates(const FlatPanel& fp, const Point2& near) {
  const Point2 centre = vertexBandCentre(fp);
  double reach = 0;
  for (const Point2& p : fp.vertexBand) reach = std::max(reach, (p - centre).norm());
  std::vector<Point2> candidates;
  for (int i = -5; i <= 5; ++i) {
    for (int j = -5; j <= 5; ++j) candidates.push_back(centre + Point2(i, j) * (reach / 5));
  }
  std::stable_sort(candidates.begin(), candidates.end(), [&](const Point2& a, const Point2& b) {
    return (a - near).squaredNorm() < (b - near).squaredNorm();
  });
  return candidates;
}

// The panel number on the vertex band, as near its centre as it fits.
void labelPanelNumber(const FlatPanel& fp, const HersheyFont& font, const std::vector<Circle>& circles,
                      std::vector<TextBox>& taken, Panel& panel, std::vector<Unetched>& unfitted,
                      double largest = kLargestLabel) {
  const std::vector<Point2> candidates = vertexBandCandidates(fp, vertexBandCentre(fp));
  const std::string label = std::to_string(panel.id);
  if (const auto box = fitText(font, labelText(label), {0.0, std::numbers::pi / 2}, fp.vertexBand, fp.outline, circles,
                               taken, candidates, largest)) {
    taken.push_back(*box);
    panel.labels.push_back(
        {labelText(label), 0, LabelRole::Panel, *box, labelStrokes(font, label, box->origin, box->height, box->angle)});
  } else {
    unfitted.push_back({fmt::format("panel number {}", panel.id), fp.bands.empty() ? -1 : fp.bands.front().edge});
  }
}

// An edge number too large for its band even at kSmallestLabel, on the
// panel's body instead (the vertex band), reading along the band, as near
// the band's root as it fits: moved, never left out (dissertation V.5: the
// builders find the matching panel by it).
void labelOnTheBody(const BandBuild& b, const FlatPanel& fp, const FlatBand& copy, const HersheyFont& font,
                    const std::vector<Circle>& circles, std::vector<TextBox>& taken, Panel& panel,
                    std::vector<Unetched>& unfitted, double largest) {
  const double near = copy.fromA ? 0.0 : 1.0, far = 1.0 - near;
  const Point2 out = copy.at(far, 0.5) - copy.at(near, 0.5);
  const int edge = b.edgeNumber[copy.edge];
  const std::string label = std::to_string(edge);
  const std::vector<Point2> candidates = vertexBandCandidates(fp, copy.at(near, 0.5));
  // Along the band, across it, then along each side of the vertex band (a
  // thin triangle's body is long only along its sides).
  std::vector<double> angles = alongThenAcross(std::atan2(out.y(), out.x()));
  for (size_t i = 0; i < fp.vertexBand.size(); ++i) {
    const Point2 side = fp.vertexBand[(i + 1) % fp.vertexBand.size()] - fp.vertexBand[i];
    angles.push_back(std::atan2(side.y(), side.x()));
  }
  if (const auto box =
          fitText(font, labelText(label), angles, fp.vertexBand, fp.outline, circles, taken, candidates, largest)) {
    taken.push_back(*box);
    panel.labels.push_back({labelText(label), edge, LabelRole::Edge, *box,
                            labelStrokes(font, label, box->origin, box->height, box->angle)});
  } else {
    unfitted.push_back({fmt::format("edge {} on panel {}", label, panel.id), copy.edge});
  }
}

// The panel's number and the edge numbers moved to its body: the number
// first, at its largest; where that leaves an edge number out, the edge
// numbers first, each near its band's root, and all of them no taller than
// a cap lowered until every one fits (or, failing that, the placing that
// leaves the fewest out).
void labelTheBody(const BandBuild& b, const FlatPanel& fp, const std::vector<const FlatBand*>& onTheBody,
                  const HersheyFont& font, const std::vector<Circle>& circles, std::vector<TextBox>& taken,
                  Panel& panel, std::vector<Unetched>& unfitted) {
  const size_t labelsBefore = panel.labels.size(), takenBefore = taken.size();
  const auto place = [&](bool numberFirst, double largest) {
    panel.labels.resize(labelsBefore);
    taken.resize(takenBefore);
    std::vector<Unetched> left;
    if (numberFirst) labelPanelNumber(fp, font, circles, taken, panel, left);
    for (const FlatBand* copy : onTheBody) labelOnTheBody(b, fp, *copy, font, circles, taken, panel, left, largest);
    if (!numberFirst) labelPanelNumber(fp, font, circles, taken, panel, left, largest);
    return left;
  };
  std::vector<Unetched> left = place(true, kLargestLabel);
  std::optional<double> fewestAt;  // the cap that left the fewest out, if not the number first
  for (const double cap : {kLargestLabel, 0.15, 0.1, kSmallestLabel}) {
    if (left.empty()) break;
    std::vector<Unetched> capped = place(false, cap);
    if (capped.size() < left.size()) left = std::move(capped), fewestAt = cap;
  }
  if (!left.empty()) fewestAt ? place(false, *fewestAt) : place(true, kLargestLabel);
  unfitted.insert(unfitted.end(), left.begin(), left.end());
}

}  // namespace

Panel bandPanel(const BandBuild& b, const std::vector<BandHoles>& holes, const HersheyFont& font, int number,
                std::vector<Unetched>& unfitted) {
  const FlatPanel& fp = b.flat[b.order.faceOfPanel[number]];
  PanelCircles circles;
  Panel panel = panelWithBands(b, holes, number, circles);
  std::vector<const FlatBand*> onTheBody;
  std::vector<TextBox> taken = labelBands(b, holes, fp, font, circles, panel, onTheBody, unfitted);
  labelTheBody(b, fp, onTheBody, font, circles.panel, taken, panel, unfitted);
  if (b.options.scoreFolds) {
    for (size_t side = 0; side < fp.bandOfSide.size(); ++side) {
      if (fp.bandOfSide[side] < 0) continue;
      panel.scores.push_back({fp.vertexBand[side], fp.vertexBand[(side + 1) % fp.vertexBand.size()]});
    }
  }
  return panel;
}

void refuseUnetched(const BandBuild& b, const std::vector<std::vector<Unetched>>& unetchedOf, Structure& result) {
  std::vector<std::vector<std::string>> whatOf(unetchedOf.size());
  std::set<int> edges;
  for (size_t panel = 0; panel < unetchedOf.size(); ++panel) {
    for (const Unetched& label : unetchedOf[panel]) {
      whatOf[panel].push_back(label.what);
      if (label.edge >= 0) edges.insert(label.edge);
    }
  }
  if (edges.empty() || b.options.glueBandsWithoutRoom) {
    if (auto warning = unetchedLabelsWarning(whatOf, "band", b.options.names.unit))
      result.warnings.push_back(std::move(*warning));
    return;
  }
  NoRoomForHoleError error =
      NoRoomForHoleError::forLabels(fmt::format("{}: its number fits on neither its band nor its panel, even at {}",
                                                b.edgeName(*edges.begin()), b.options.names.unit(kSmallestLabel, 3)),
                                    static_cast<int>(edges.size()), b.options.names);
  error.edges.assign(edges.begin(), edges.end());
  throw b.withPlaces(error);
}

}  // namespace rotafab::geometry::band
