#include "geometry/WeaveParts.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/Polygon2.h"
#include "geometry/PanelLabels.h"

namespace rotafab::geometry::weaving {

namespace {

// Rows first..last of a panel's strip.
struct RowSpan {
  int first = 0, last = 0;
  [[nodiscard]] bool holds(int row) const { return row >= first && row <= last; }
};

// A piece's name, from its middle row outwards, reading along the thread
// there (a piece is short: its rows turn little), clear of its holes and labels.
std::optional<PanelLabel> pieceName(const WovenPanel& w, const RowSpan& span, const PanelPiece& piece,
                                    const HersheyFont& font) {
  std::vector<Circle> circles;
  for (const PanelHole& hole : piece.holes) circles.push_back({hole.xy, hole.diameter / 2});
  std::vector<TextBox> taken;
  for (const PanelLabel& label : piece.labels) taken.push_back(label.box);
  const int middle = (span.first + span.last) / 2;
  std::vector<int> rows{middle};
  for (int k = 1; middle - k >= span.first || middle + k <= span.last; ++k) {
    for (int row : {middle - k, middle + k}) {
      if (row >= span.first && row <= span.last) rows.push_back(row);
    }
  }
  const auto box = fitText(font, piece.name, alongThenAcross(angleAtRow(w, middle)), piece.outline, piece.outline,
                           circles, taken, labelCandidates(w, rows));
  if (!box) return std::nullopt;
  return PanelLabel{piece.name, 0, LabelRole::Piece, *box,
                    font.strokes(piece.name, box->origin, box->height, box->angle)};
}

}  // namespace

void cutApart(const WovenPanel& w, Panel& panel, const std::vector<int>& holeRows, const std::vector<int>& labelRows,
              double diameter, const HersheyFont& font, std::vector<std::string>& unfitted) {
  constexpr int kLongestLap = 4, kCuts = 2;
  std::vector<RowSpan> spans{{0, w.rows() - 1}};
  std::vector<int> laps;  // the row of each cut's hole
  const auto crosses = [&](const RowSpan& span) { return core::crossesItself(w.outlineOfRows(span.first, span.last)); };
  // Whether the parts `a` and `b` of a cut with its hole at row `c` keep
  // every hole clear and hold every label; how many of them still cross themselves.
  const auto tryCut = [&](const RowSpan& a, const RowSpan& b, int c) -> int {
    const std::vector<Point2> outlineA = w.outlineOfRows(a.first, a.last), outlineB = w.outlineOfRows(b.first, b.last);
    const Point2 lap = centreOfRow(w, c);
    for (const auto* outline : {&outlineA, &outlineB}) {
      if (core::distanceToOutline(*outline, lap) < kClearance * diameter) return -1;
    }
    // Clear of the earlier cuts' holes, and of every label (they were fitted before any lap).
    for (int earlier : laps) {
      if ((centreOfRow(w, earlier) - lap).norm() < (kLeastClearance + 1) * diameter) return -1;
    }
    for (const PanelLabel& label : panel.labels) {
      if (label.box.distanceTo(lap) < diameter / 2 + kLabelGap) return -1;
    }
    for (size_t h = 0; h < panel.holes.size(); ++h) {
      // Only what the span being cut holds: the rest is on the other parts.
      if (!a.holds(holeRows[h]) && !b.holds(holeRows[h])) continue;
      // A crossing's hole on one part only: its three panels hold one each.
      if (a.holds(holeRows[h]) && b.holds(holeRows[h])) return -1;
      for (const auto& [span, outline] : {std::pair{a, &outlineA}, std::pair{b, &outlineB}}) {
        if (!span.holds(holeRows[h])) continue;
        if (core::distanceToOutline(*outline, panel.holes[h].xy) < kLeastClearance * diameter) return -1;
        if ((panel.holes[h].xy - lap).norm() < (kLeastClearance + 1) * diameter) return -1;
      }
    }
    for (size_t l = 0; l < panel.labels.size(); ++l) {
      if (!a.holds(labelRows[l]) && !b.holds(labelRows[l])) continue;
      bool held = false;
      for (const auto& part : {std::pair{a, &outlineA}, std::pair{b, &outlineB}}) {
        // (Not a structured binding: a lambda below uses the outline, which clang 14 refuses to capture.)
        const RowSpan& span = part.first;
        const std::vector<Point2>* outline = part.second;
        if (!span.holds(labelRows[l])) continue;
        const auto corners = panel.labels[l].box.corners();
        held = held || std::all_of(corners.begin(), corners.end(),
                                   [&](const Point2& p) { return core::insidePolygon(*outline, p); });
      }
      if (!held) return -1;
    }
    return (core::crossesItself(outlineA) ? 1 : 0) + (core::crossesItself(outlineB) ? 1 : 0);
  };
  for (int cuts = 0; cuts < kCuts; ++cuts) {
    const auto overlapping = std::find_if(spans.begin(), spans.end(), crosses);
    if (overlapping == spans.end()) break;
    const RowSpan span = *overlapping;
    // Cuts from the middle of the span outwards, the shortest lap first that keeps the lap's hole clear.
    std::vector<int> rows;
    const int middle = (span.first + span.last) / 2;
    for (int k = 0; k <= (span.last - span.first) / 2; ++k) {
      for (int c : {middle - k, middle + k}) {
        if (c > span.first + 1 && c < span.last - 1 && (rows.empty() || rows.back() != c)) rows.push_back(c);
      }
    }
    int bestScore = 3, bestRow = -1, bestLap = 0;
    for (int c : rows) {
      for (int lap = 1; lap <= kLongestLap && bestScore > 0; ++lap) {
        if (c - lap <= span.first || c + lap >= span.last) break;
        const int score = tryCut({span.first, c + lap}, {c - lap, span.last}, c);
        if (score >= 0 && score < bestScore) bestScore = score, bestRow = c, bestLap = lap;
        if (score >= 0) break;  // a longer lap only spends material
      }
      if (bestScore == 0) break;
    }
    if (bestRow < 0) break;
    *overlapping = {span.first, bestRow + bestLap};
    spans.insert(overlapping + 1, RowSpan{bestRow - bestLap, span.last});
    laps.push_back(bestRow);
  }
  if (laps.empty() || std::any_of(spans.begin(), spans.end(), crosses)) return;

  // The part over the panel's edge stays the panel.
  std::sort(laps.begin(), laps.end());
  const auto main = std::find_if(spans.begin(), spans.end(), [&](const RowSpan& span) { return span.holds(w.upRow); });
  const std::vector<PanelHole> holes = panel.holes;
  std::vector<PanelLabel> labels = panel.labels;
  const auto holesOf = [&](const RowSpan& span) {
    std::vector<PanelHole> mine;
    for (size_t h = 0; h < holes.size(); ++h) {
      if (span.holds(holeRows[h])) mine.push_back(holes[h]);
    }
    for (int c : laps) {
      if (span.holds(c)) mine.push_back({0, centreOfRow(w, c), diameter});  // a tab's fastener: no edge
    }
    return mine;
  };
  std::vector<char> labelTaken(labels.size(), 0);
  const auto labelsOf = [&](const RowSpan& span) {
    const std::vector<Point2> outline = w.outlineOfRows(span.first, span.last);
    std::vector<PanelLabel> mine;
    for (size_t l = 0; l < labels.size(); ++l) {
      if (labelTaken[l] || !span.holds(labelRows[l])) continue;
      const auto corners = labels[l].box.corners();
      if (!std::all_of(corners.begin(), corners.end(),
                       [&](const Point2& p) { return core::insidePolygon(outline, p); })) {
        continue;
      }
      labelTaken[l] = 1;
      mine.push_back(labels[l]);
    }
    return mine;
  };
  panel.outline = w.outlineOfRows(main->first, main->last);
  panel.holes = holesOf(*main);
  panel.labels = labelsOf(*main);
  panel.area = w.areaOfRows(main->first, main->last);
  char letter = 'a';
  for (auto span = spans.begin(); span != spans.end(); ++span) {
    if (span == main) continue;
    PanelPiece piece;
    piece.name = fmt::format("{}{}", panel.id, letter++);
    piece.edge = panel.id;
    piece.outline = w.outlineOfRows(span->first, span->last);
    piece.holes = holesOf(*span);
    piece.labels = labelsOf(*span);
    piece.area = w.areaOfRows(span->first, span->last);
    piece.fastening = PieceFastening::Tab;
    if (auto name = pieceName(w, *span, piece, font)) {
      piece.labels.push_back(std::move(*name));
    } else {
      unfitted.push_back(fmt::format("piece {}", piece.name));
    }
    panel.pieces.push_back(std::move(piece));
  }
}

}  // namespace rotafab::geometry::weaving
