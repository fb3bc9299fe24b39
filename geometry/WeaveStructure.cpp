#include "geometry/WeaveStructure.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <set>

#include "core/Polygon2.h"
#include "geometry/FastenerHoles.h"
#include "geometry/FloodFill.h"
#include "geometry/HersheyFont.h"
#include "geometry/PanelLabels.h"
#include "geometry/RibbonCollisions.h"
#include "geometry/WovenPanels.h"

namespace rotafab::geometry {
namespace {

std::string plural(size_t n) { return n == 1 ? "" : "s"; }

// The three panels of a crossing: over it, and under it before and after
// it along the thread under (indices into the woven panels), each with the
// row of its strip through the crossing.
struct CrossingPanels {
  std::array<int, 3> panel{-1, -1, -1};
  std::array<int, 3> row{};
};

// The order of the threads (docs/WEAVE.md, M11): the thread over the lowest
// crossing first, then each time the thread crossing most of those placed
// (the first on a tie), so that each thread is woven into the ones before.
std::vector<int> threadOrder(const WeaveThreads& weave, const std::vector<EdgeRegion>& regions, int up) {
  const int threads = static_cast<int>(weave.threads.size());
  int lowest = -1;
  for (size_t e = 0; e < regions.size(); ++e) {
    if (weave.up[e].thread < 0) continue;
    if (lowest < 0 || regions[e].midpoint[up] < regions[static_cast<size_t>(lowest)].midpoint[up]) {
      lowest = static_cast<int>(e);
    }
  }
  std::vector<int> order;
  std::vector<char> placed(static_cast<size_t>(threads), 0);
  std::vector<int> shared(static_cast<size_t>(threads), 0);
  // Max-heap of (crossings shared with placed threads, -thread), stale entries skipped.
  std::priority_queue<std::pair<int, int>> next;
  const auto place = [&](int t) {
    placed[static_cast<size_t>(t)] = 1;
    order.push_back(t);
    for (const ThreadStep& step : weave.threads[static_cast<size_t>(t)].steps) {
      if (step.crossing == Crossing::None) continue;
      const size_t e = static_cast<size_t>(RotationSystem::edgeOf(step.dart));
      const int other = step.crossing == Crossing::Up ? weave.down[e].thread : weave.up[e].thread;
      if (placed[static_cast<size_t>(other)]) continue;
      next.emplace(++shared[static_cast<size_t>(other)], -other);
    }
  };
  for (int start = lowest >= 0 ? weave.up[static_cast<size_t>(lowest)].thread : 0; start >= 0;) {
    place(start);
    while (!next.empty()) {
      const auto [count, negative] = next.top();
      next.pop();
      const int t = -negative;
      if (placed[static_cast<size_t>(t)] || count != shared[static_cast<size_t>(t)]) continue;
      place(t);
    }
    // A surface of several pieces: go on with a thread not reached.
    const auto missed = std::find(placed.begin(), placed.end(), 0);
    start = missed == placed.end() ? -1 : static_cast<int>(missed - placed.begin());
  }
  return order;
}

Point2 centreOfRow(const WovenPanel& panel, int row) {
  row = std::clamp(row, 0, panel.rows() - 1);
  return (panel.flatP[static_cast<size_t>(row)] + panel.flatQ[static_cast<size_t>(row)]) / 2;
}

// The direction the thread runs at `row`, flat.
double angleAtRow(const WovenPanel& panel, int row) {
  const Point2 along = centreOfRow(panel, row + 1) - centreOfRow(panel, row - 1);
  return std::atan2(along.y(), along.x());
}

// The flat hole positions of one crossing on its three panels, and the
// clearance they keep, in diameters: from each panel's outline, and
// between the two holes on a panel less one diameter (kClearance from the
// outline and kClearance + 1 between centres keep the same 1.5 diameters
// of material, FastenerHoles.h).
struct CrossingHoles {
  std::array<std::array<Point2, 2>, 3> flat;  // per panel of CrossingPanels, per hole
  std::array<std::array<int, 2>, 3> rows{};   // the strip row each lies on
  double clearance = -std::numeric_limits<double>::infinity();
  double fromOutline = 0, apart = 0;  // the least distance to an outline, and between a panel's two holes, diameters
  bool single = false;                // one hole at the crossing's centre: no room for two

  // How many times larger the mesh must be (every length but the
  // diameter grows with it) for these holes to have room: kLeastClearance,
  // with 2% to spare, as for a band (FastenerHoles.h).
  [[nodiscard]] double scaleNeeded() const {
    constexpr double kSpare = 1.02;
    return std::max(fromOutline > 0 ? kSpare * kLeastClearance / fromOutline : std::numeric_limits<double>::infinity(),
                    apart > 0 ? kSpare * (kLeastClearance + 1) / apart : std::numeric_limits<double>::infinity());
  }
};

CrossingHoles holesAt(const EdgeRegion& region, const CrossingPanels& at, const std::vector<WovenPanel>& panels,
                      const std::vector<std::vector<Point2>>& outlines, double delta, int reach, double diameter) {
  CrossingHoles holes;
  double fromOutline = std::numeric_limits<double>::infinity(), apart = fromOutline;
  bool missed = false;
  for (size_t k = 0; k < 3; ++k) {
    const WovenPanel& panel = panels[static_cast<size_t>(at.panel[k])];
    for (size_t h = 0; h < 2; ++h) {
      // On the over strand's centre line, either side of the crossing's
      // centre (docs/WEAVE.md, 1.11): along the over panel, across the
      // panels under it.
      const Point3 point = region.at(0.5 + (h == 0 ? -delta : delta), 0.5);
      const StripPoint hit = stripPointOnLine(panel, at.row[k] - reach, at.row[k] + reach, point, region.normal);
      holes.flat[k][h] = hit.onPanel(panel);
      holes.rows[k][h] =
          std::min({hit.corners[0] % panel.rows(), hit.corners[1] % panel.rows(), hit.corners[2] % panel.rows()});
      // A line that misses the strip: no hole through all three panels there.
      missed = missed || hit.miss > 1e-6 * diameter;
      fromOutline =
          std::min(fromOutline,
                   core::distanceToOutline(outlines[static_cast<size_t>(at.panel[k])], holes.flat[k][h]) / diameter);
    }
    apart = std::min(apart, (holes.flat[k][0] - holes.flat[k][1]).norm() / diameter);
  }
  holes.fromOutline = missed ? 0 : fromOutline;
  holes.apart = apart;
  holes.clearance = missed ? -std::numeric_limits<double>::infinity() : std::min(fromOutline, apart - 1);
  return holes;
}

// The largest spread of a crossing's holes, from a quarter of the quad's
// smaller side (in the region's parameters) down to where their centres are
// kClearance + 1 diameters apart, that keeps kClearance diameters to every
// outline; else the spread that keeps the most.
CrossingHoles placeCrossingHoles(const EdgeRegion& region, const CrossingPanels& at,
                                 const std::vector<WovenPanel>& panels,
                                 const std::vector<std::vector<Point2>>& outlines, const RibbonShape& shape,
                                 double diameter) {
  const double largest = std::min(shape.curve, shape.width) / 4;
  const double length = (region.at(1, 0.5) - region.at(0, 0.5)).norm();
  const double smallest = std::min(largest, (kClearance + 1) * diameter / (2 * length));
  const int reach = std::max(1, shape.samples / 2);
  constexpr int kTries = 8;
  CrossingHoles best;
  for (int i = 0; i <= kTries; ++i) {
    const double delta = largest + (smallest - largest) * i / kTries;
    CrossingHoles holes = holesAt(region, at, panels, outlines, delta, reach, diameter);
    if (holes.clearance >= kClearance) return holes;
    if (holes.clearance > best.clearance) best = holes;
  }
  if (best.clearance >= kLeastClearance) return best;
  // No room for two: one at the crossing's centre, as a band too small for
  // two holes gets one (FastenerHoles.h), if that has room.
  CrossingHoles one = holesAt(region, at, panels, outlines, 0, reach, diameter);
  one.single = true;
  one.apart = std::numeric_limits<double>::infinity();
  one.clearance = one.fromOutline > 0 ? one.fromOutline : -std::numeric_limits<double>::infinity();
  return one.clearance > best.clearance || one.clearance >= kLeastClearance ? one : best;
}

// The rows from `from` stepping towards `to`, both included, those on the panel.
std::vector<int> rowsFrom(const WovenPanel& panel, int from, int to) {
  std::vector<int> rows;
  const int step = to >= from ? 1 : -1;
  for (int row = from;; row += step) {
    if (row >= 0 && row < panel.rows()) rows.push_back(row);
    if (row == to) break;
  }
  return rows;
}

// The candidate centres for a label, row by row in the order given: on
// each row its middle, then nearer one side and the other (a label beside
// a hole rather than between two).
std::vector<Point2> labelCandidates(const WovenPanel& panel, const std::vector<int>& rows) {
  std::vector<Point2> candidates;
  for (int row : rows) {
    const Point2 &p = panel.flatP[static_cast<size_t>(row)], &q = panel.flatQ[static_cast<size_t>(row)];
    for (double t : {0.5, 0.25, 0.75}) candidates.push_back(p + t * (q - p));
  }
  return candidates;
}

// Rows first..last of a panel's strip.
struct RowSpan {
  int first = 0, last = 0;
  [[nodiscard]] bool holds(int row) const { return row >= first && row <= last; }
};

// A panel whose unfolded outline crosses itself (its ribbon curls round, as
// round a face at a leaf of a single thread's tree, or round a sharp vertex)
// is cut across its strip, at most twice, into parts that do not; each cut
// leaves the two parts overlapping over a few rows (a lap) with one hole
// through both. The parts keep the panel's flat frame (an unfolding of
// some of its rows is the same as theirs in the whole), so its holes and
// labels stay where they are, each on the part whose rows hold it (a hole
// in a lap on both). The part over the panel's edge stays the panel; the
// others become its pieces, "17a", "17b", each with its name etched on it
// (as a band's piece on its tab; `unfitted` names those it does not fit).
// Leaves the panel as it was when no cut gives parts that keep their holes'
// clearance and hold their labels.
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
  // A piece's name, from its middle row outwards, reading along the thread
  // there (a piece is short: its rows turn little), clear of its holes and labels.
  const auto pieceName = [&](const RowSpan& span, const PanelPiece& piece) -> std::optional<PanelLabel> {
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
    const auto box = fitText(font, piece.name, angleAtRow(w, middle), piece.outline, piece.outline, circles, taken,
                             labelCandidates(w, rows));
    if (!box) return std::nullopt;
    return PanelLabel{piece.name, 0, LabelRole::Piece, *box,
                      font.strokes(piece.name, box->origin, box->height, box->angle)};
  };
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
    if (auto name = pieceName(*span, piece)) {
      piece.labels.push_back(std::move(*name));
    } else {
      unfitted.push_back(fmt::format("piece {}", piece.name));
    }
    panel.pieces.push_back(std::move(piece));
  }
}

}  // namespace

std::vector<AssemblyStep> weaveSteps(const std::vector<Panel>& panels) {
  // Per edge number: its holes in all, and the last panel holding some
  // (on itself or a piece of it). A crossing's three panels hold as many
  // holes each, one per fastener; a panel may be two of them (a single
  // thread round a leaf face of its tree goes under and then over one edge).
  // Holes of edge 0 fasten a piece to its panel.
  std::map<int, int> holesOfEdge, lastPanel, firstPanel;
  const auto count = [&](const PanelHole& hole, int id) {
    if (hole.edge == 0) return;
    ++holesOfEdge[hole.edge];
    lastPanel[hole.edge] = std::max(lastPanel[hole.edge], id);
    if (!firstPanel.count(hole.edge)) firstPanel[hole.edge] = id;
  };
  for (const Panel& panel : panels) {
    for (const PanelHole& hole : panel.holes) count(hole, panel.id);
    for (const PanelPiece& piece : panel.pieces) {
      for (const PanelHole& hole : piece.holes) count(hole, panel.id);
    }
  }
  std::vector<AssemblyStep> steps;
  for (const Panel& panel : panels) {
    AssemblyStep step{panel.id, {}, {}, {}};
    std::set<int> edges;
    for (const PanelHole& hole : panel.holes) edges.insert(hole.edge);
    for (const PanelPiece& piece : panel.pieces) {
      for (const PanelHole& hole : piece.holes) edges.insert(hole.edge);
      if (piece.fastening == PieceFastening::Tab) step.pieces.push_back(piece.name);
    }
    edges.erase(0);
    for (int edge : edges) {
      if (lastPanel[edge] != panel.id) continue;
      // The join names the panel over it, or at the over panel's own step the first under it.
      const int named = edge != panel.id ? edge : firstPanel[edge];
      step.joins.push_back({named, edge, holesOfEdge[edge] / 3, {}});
    }
    steps.push_back(std::move(step));
  }
  return steps;
}

Structure buildWeaveStructure(const PolygonMesh& mesh, const WeaveOptions& options, const core::WorkContext& context) {
  if (!(options.fastener > 0)) {
    throw ParameterError(Parameter::Fastener,
                         fmt::format("{}: the hole diameter must be positive", options.names(Parameter::Fastener)));
  }
  context.report({"geometry", "weaving threads", 0, 0});
  RotationSystem rs = RotationSystem::fromMesh(mesh);
  twistForWeave(rs, options.cycles, lowestFace(mesh, options.up));
  const WeaveThreads weave = traceThreads(rs);
  const std::vector<EdgeRegion> regions = edgeRegions(mesh, rs);
  context.check();
  context.report({"geometry", "ribbons", 0, 0});
  // Ribbons that pass through each other (ch. VII's open problem):
  // narrowed where they would, or, at a width asked for, warned of with the
  // width that clears them.
  std::vector<Ribbon> ribbons;
  std::vector<double> edgeWidths;
  RibbonCollisions collisions;
  int narrowed = 0;
  if (options.narrowWhereRibbonsMeet) {
    context.report({"geometry", "ribbons that meet", 0, 0});
    ClearedRibbons cleared = narrowUntilClear(rs, weave, regions, options.shape, context);
    ribbons = std::move(cleared.ribbons);
    edgeWidths = std::move(cleared.edgeWidths);
    collisions = std::move(cleared.left);
    narrowed = cleared.narrowed;
  } else {
    ribbons = weaveRibbons(rs, weave, regions, options.shape);
    edgeWidths.assign(regions.size(), options.shape.width);
    context.report({"geometry", "ribbons that meet", 0, 0});
    collisions = ribbonCollisions(rs, weave, regions, ribbons, options.shape, context);
  }
  const int overlap = std::max(1, options.shape.samples / 2);
  std::vector<WovenPanel> woven = wovenPanels(ribbons, regions, overlap);
  context.check();

  // Assembly order: thread by thread, each from its lowest crossing over.
  const int up = options.up;
  std::vector<std::vector<int>> panelsOfThread(ribbons.size());
  for (size_t i = 0; i < woven.size(); ++i)
    panelsOfThread[static_cast<size_t>(woven[i].thread)].push_back(static_cast<int>(i));
  std::vector<int> order;  // panel id - 1 -> woven index
  std::vector<int> cycleOf(ribbons.size(), 0);
  int cycle = 0;
  for (int t : threadOrder(weave, regions, up)) {
    auto& mine = panelsOfThread[static_cast<size_t>(t)];
    cycleOf[static_cast<size_t>(t)] = ++cycle;
    if (mine.empty()) continue;
    const auto lowest = std::min_element(mine.begin(), mine.end(), [&](int a, int b) {
      return regions[static_cast<size_t>(woven[static_cast<size_t>(a)].upEdge)].midpoint[up] <
             regions[static_cast<size_t>(woven[static_cast<size_t>(b)].upEdge)].midpoint[up];
    });
    std::rotate(mine.begin(), lowest, mine.end());
    order.insert(order.end(), mine.begin(), mine.end());
  }
  std::vector<int> idOf(woven.size());
  std::vector<int> edgeNumber(regions.size(), 0);
  for (size_t k = 0; k < order.size(); ++k) {
    idOf[static_cast<size_t>(order[k])] = static_cast<int>(k) + 1;
    edgeNumber[static_cast<size_t>(woven[static_cast<size_t>(order[k])].upEdge)] = static_cast<int>(k) + 1;
  }

  // Each crossing's three panels.
  std::vector<CrossingPanels> crossings(regions.size());
  for (size_t i = 0; i < woven.size(); ++i) {
    const WovenPanel& p = woven[i];
    crossings[static_cast<size_t>(p.upEdge)].panel[0] = static_cast<int>(i);
    crossings[static_cast<size_t>(p.upEdge)].row[0] = p.upRow;
    // Under before the crossing (it ends there) and after it (it starts there).
    crossings[static_cast<size_t>(p.downEdges[1])].panel[1] = static_cast<int>(i);
    crossings[static_cast<size_t>(p.downEdges[1])].row[1] = p.downRows[1];
    crossings[static_cast<size_t>(p.downEdges[0])].panel[2] = static_cast<int>(i);
    crossings[static_cast<size_t>(p.downEdges[0])].row[2] = p.downRows[0];
  }
  std::vector<std::vector<Point2>> outlines(woven.size());
  context.parallelFor(woven.size(), [&](size_t i) { outlines[i] = woven[i].outline(); });

  Structure result;
  result.kind = StructureKind::Weave;
  result.edges = static_cast<int>(woven.size());
  const double d = options.fastener;
  const size_t crossingCount = regions.size();
  context.report({"geometry", "crossing holes", 0, static_cast<size_t>(result.edges)});
  std::vector<CrossingHoles> holes(crossingCount);
  std::vector<char> glued(crossingCount, 0);
  context.parallelFor(crossingCount, [&](size_t e) {
    if (crossings[e].panel[0] < 0) return;  // untwisted: no crossing
    RibbonShape shape = options.shape;
    shape.width = edgeWidths[e];
    holes[e] = placeCrossingHoles(regions[e], crossings[e], woven, outlines, shape, d);
  });
  {
    int withoutRoom = 0, narrow = 0, single = 0;
    double scaleNeeded = 1, narrowest = kClearance;
    int first = 0, narrowestEdge = 0;
    std::vector<double> scales;
    for (size_t e = 0; e < crossingCount; ++e) {
      if (crossings[e].panel[0] < 0) continue;
      const double c = holes[e].clearance;
      if (c < kLeastClearance) {
        ++withoutRoom;
        const double scale = holes[e].scaleNeeded();
        scales.push_back(scale);
        if (first == 0 || scale > scaleNeeded) first = edgeNumber[e];
        scaleNeeded = std::max(scaleNeeded, scale);
      } else if (holes[e].single) {
        ++single;
      } else if (c < kClearance) {
        ++narrow;
        if (c < narrowest) narrowest = c, narrowestEdge = edgeNumber[e];
      }
    }
    // As a band decomposition may glue a few bands (MakeJob's sizing), one
    // crossing in a hundred may go without a hole, glued, rather than the
    // whole structure grow for a sliver: the mesh grows only as far as all
    // but those need.
    const size_t mayGlue = static_cast<size_t>(result.edges) / 100;
    if (withoutRoom > 0 && (options.glueCrossingsWithoutRoom || static_cast<size_t>(withoutRoom) <= mayGlue)) {
      for (size_t e = 0; e < crossingCount; ++e) {
        if (crossings[e].panel[0] >= 0 && holes[e].clearance < kLeastClearance) {
          glued[e] = 1;
          result.glued.push_back(edgeNumber[e]);
        }
      }
      std::sort(result.glued.begin(), result.glued.end());
      std::string some;
      for (size_t i = 0; i < std::min<size_t>(result.glued.size(), 5); ++i) {
        some += fmt::format("{}{}", i ? ", " : "", result.glued[i]);
      }
      result.warnings.push_back(fmt::format(
          "{} crossing{} no room for a {:.3f} in fastener hole {:g} diameter from its panels' outlines, so no "
          "hole: glue {} (edge{} {}{})",
          withoutRoom, withoutRoom == 1 ? " has" : "s have", d, kLeastClearance, withoutRoom == 1 ? "it" : "them",
          withoutRoom == 1 ? "" : "s", some, result.glued.size() > 5 ? ", ..." : ""));
      withoutRoom = 0;
    }
    if (withoutRoom > 0) {
      std::sort(scales.begin(), scales.end(), std::greater<>());
      scaleNeeded = scales[std::min(mayGlue, scales.size() - 1)];
      NoRoomForHoleError error(
          fmt::format("edge {}: its crossing has no room for two {:.3f} in holes {:g} diameter from the outlines of "
                      "its three panels{}",
                      first, d, kLeastClearance,
                      withoutRoom > 1 ? fmt::format(" (nor have {} other crossings)", withoutRoom - 1) : ""),
          1, scaleNeeded, d, options.names);
      error.bands = withoutRoom;
      error.scales = scales;
      throw error;
    }
    if (single > 0) {
      result.warnings.push_back(fmt::format(
          "{} crossing{} too small for two {:.3f} in holes: one at {} centre, through its three panels; a larger {} "
          "or a smaller {} gives {} two",
          single, single == 1 ? " is" : "s are", d, single == 1 ? "its" : "each one's", options.names(Parameter::Size),
          options.names(Parameter::Fastener), single == 1 ? "it" : "them"));
    }
    if (narrow > 0) {
      result.warnings.push_back(fmt::format(
          "{} crossing{} too narrow for {:.3f} in holes {} diameters from the panels' outlines, down to {:.2f} "
          "diameters (edge {}); a larger {} or a smaller {} gives them the full clearance",
          narrow, narrow == 1 ? " is" : "s are", d, kClearance, narrowest, narrowestEdge,
          options.names(Parameter::Size), options.names(Parameter::Fastener)));
    }
  }
  context.check();

  // Per panel, its holes: two (or one) at each of its three crossings.
  std::vector<std::vector<PanelHole>> holesOf(woven.size());
  std::vector<std::vector<int>> holeRowsOf(woven.size());
  for (size_t e = 0; e < crossingCount; ++e) {
    if (crossings[e].panel[0] < 0 || glued[e]) continue;
    for (size_t k = 0; k < 3; ++k) {
      for (size_t h = 0; h < (holes[e].single ? 1U : 2U); ++h) {
        holesOf[static_cast<size_t>(crossings[e].panel[k])].push_back({edgeNumber[e], holes[e].flat[k][h], d});
        holeRowsOf[static_cast<size_t>(crossings[e].panel[k])].push_back(holes[e].rows[k][h]);
      }
    }
  }

  context.report({"geometry", "labels", 0, woven.size()});
  const HersheyFont& font = HersheyFont::simplex();
  result.panels.resize(woven.size());
  std::vector<std::vector<std::string>> unfittedOf(woven.size());
  std::vector<char> stillFolded(woven.size(), 0);  // per panel: crosses itself even cut
  const int reach = std::max(1, options.shape.samples / 2);
  context.parallelFor(order.size(), [&](size_t k) {
    const size_t i = static_cast<size_t>(order[k]);
    const WovenPanel& w = woven[i];
    Panel panel;
    panel.id = static_cast<int>(k) + 1;
    panel.source.edge = panel.id;
    panel.source.cycle = cycleOf[static_cast<size_t>(w.thread)];
    panel.outline = outlines[i];
    panel.holes = holesOf[i];
    panel.area = w.area;
    // A quad per row, (P_r+1, P_r, Q_r, Q_r+1): its fan from the first
    // corner is the strip's two triangles (P_r, Q_r, P_r+1), (Q_r, Q_r+1,
    // P_r+1), as they were unfolded; half the polygons of two triangles
    // (a 50,000-face weave keeps 3.6 million rows).
    panel.surface.reserve(static_cast<size_t>(std::max(0, w.rows() - 1)));
    for (size_t r = 0; r + 1 < w.railP.size(); ++r) {
      panel.surface.push_back({w.railP[r + 1], w.railP[r], w.railQ[r], w.railQ[r + 1]});
    }
    // Joins: under it at its up crossing, and over it and on its own thread at each end.
    const CrossingPanels& atUp = crossings[static_cast<size_t>(w.upEdge)];
    for (size_t j : {1, 2}) panel.joins.push_back({idOf[static_cast<size_t>(atUp.panel[j])], panel.id});
    for (int e : w.downEdges) {
      const CrossingPanels& atDown = crossings[static_cast<size_t>(e)];
      for (size_t j : {0, 1, 2}) {
        const int other = idOf[static_cast<size_t>(atDown.panel[j])];
        if (other != panel.id) panel.joins.push_back({other, edgeNumber[static_cast<size_t>(e)]});
      }
    }

    // Labels (IV.4, fig. 39-43): the up edge's number in the middle, each
    // down edge's at its end, all reading along the thread; the
    // neighbouring edge's number underlined beside the middle one
    // (docs/WEAVE.md, 1.12, A12).
    std::vector<Circle> circles;
    for (const PanelHole& hole : panel.holes) circles.push_back({hole.xy, hole.diameter / 2});
    std::vector<TextBox> taken;
    std::vector<int> labelRows;
    const auto place = [&](const std::string& label, int edge, LabelRole role, int row, int first, int last,
                           const std::vector<Point2>& candidates) {
      const std::vector<Point2> region = w.outlineOfRows(std::max(first, 0), std::min(last, w.rows() - 1));
      const std::string text = labelText(label);
      const auto box = fitText(font, text, angleAtRow(w, row), region, panel.outline, circles, taken, candidates);
      if (!box) {
        unfittedOf[i].push_back(fmt::format("{} {} on panel {}", roleName(role), label, panel.id));
        return;
      }
      taken.push_back(*box);
      PanelLabel placed{text, edge, role, *box, labelStrokes(font, label, box->origin, box->height, box->angle)};
      if (role == LabelRole::Neighbor) {
        // Underlined: a stroke below the box, within the gap fitText kept.
        const Point2 below = Point2(box->along.y(), -box->along.x()) * (box->height * 0.15);
        placed.strokes.push_back({box->origin + below, box->origin + box->along * box->width + below});
      }
      panel.labels.push_back(std::move(placed));
      // Its row: the one whose centre is nearest the box's.
      const Point2 centre =
          box->origin + box->along * box->width / 2 + Point2(-box->along.y(), box->along.x()) * box->height / 2;
      int nearest = std::clamp(first, 0, w.rows() - 1);
      for (int r = std::max(first, 0); r <= std::min(last, w.rows() - 1); ++r) {
        if ((centreOfRow(w, r) - centre).norm() < (centreOfRow(w, nearest) - centre).norm()) nearest = r;
      }
      labelRows.push_back(nearest);
    };
    const int u = w.upRow;
    {
      // From the middle row outwards, either way in turn.
      std::vector<int> rows{u};
      for (int k = 1; k <= reach; ++k) {
        for (int row : {u - k, u + k}) {
          if (row >= 0 && row < w.rows()) rows.push_back(row);
        }
      }
      place(std::to_string(panel.id), panel.id, LabelRole::Up, u, u - reach, u + reach, labelCandidates(w, rows));
    }
    // The neighbouring edge: the panel under this one met first turning
    // counter-clockwise about N_e from the direction this one runs.
    {
      const RibbonPass& over = ribbons[static_cast<size_t>(w.thread)].passes[static_cast<size_t>(w.upPass)];
      const StepRef under = weave.down[static_cast<size_t>(w.upEdge)];
      const RibbonPass& below = ribbons[static_cast<size_t>(under.thread)].passes[static_cast<size_t>(under.step)];
      const Point3 overRuns = (over.tail[0] + over.tail[1]) - (over.head[0] + over.head[1]);
      const Point3 underRuns = (below.tail[0] + below.tail[1]) - (below.head[0] + below.head[1]);
      const bool after = overRuns.cross(underRuns).dot(regions[static_cast<size_t>(w.upEdge)].normal) > 0;
      const int neighbour = idOf[static_cast<size_t>(atUp.panel[after ? 2 : 1])];
      std::vector<int> rows = rowsFrom(w, u + 1, u + reach);
      const auto other = rowsFrom(w, u - 1, u - reach);
      rows.insert(rows.end(), other.begin(), other.end());
      place(std::to_string(neighbour), neighbour, LabelRole::Neighbor, u, u - reach, u + reach,
            labelCandidates(w, rows));
    }
    for (int end = 0; end < 2; ++end) {
      const int row = w.downRows[static_cast<size_t>(end)];
      const int number = edgeNumber[static_cast<size_t>(w.downEdges[static_cast<size_t>(end)])];
      // Past the holes towards the panel's end first, then towards its middle.
      const int outwards = end == 0 ? -1 : 1;
      std::vector<int> rows = rowsFrom(w, row + outwards, row + outwards * reach);
      const auto inwards = rowsFrom(w, row - outwards, row - outwards * reach);
      rows.insert(rows.end(), inwards.begin(), inwards.end());
      place(std::to_string(number), number, LabelRole::Down, row, row - reach, row + reach, labelCandidates(w, rows));
    }
    if (core::crossesItself(panel.outline)) {
      cutApart(w, panel, holeRowsOf[i], labelRows, d, font, unfittedOf[i]);
      stillFolded[k] = core::crossesItself(panel.outline) ? 1 : 0;
    }
    result.panels[k] = std::move(panel);
  });
  std::vector<std::string> unfitted;
  for (auto& some : unfittedOf) unfitted.insert(unfitted.end(), some.begin(), some.end());
  if (!unfitted.empty()) {
    std::string some;
    for (size_t i = 0; i < unfitted.size() && i < 3; ++i) some += (i ? ", " : "") + unfitted[i];
    result.warnings.push_back(fmt::format("{} label{} not etched, too large for {} ribbon even at {} in: {}{}",
                                          unfitted.size(), unfitted.size() == 1 ? " is" : "s are",
                                          unfitted.size() == 1 ? "its" : "their", kSmallestLabel, some,
                                          unfitted.size() > 3 ? ", ..." : ""));
  }
  {
    std::vector<int> overlapping;
    for (size_t k = 0; k < result.panels.size(); ++k) {
      if (stillFolded[k]) overlapping.push_back(result.panels[k].id);
    }
    if (!overlapping.empty()) {
      std::string some;
      for (size_t i = 0; i < overlapping.size() && i < 5; ++i)
        some += fmt::format("{}{}", i ? ", " : "", overlapping[i]);
      // Not a panel anyone could cut and build: its ribbon folds over
      // itself, mostly where it turns about a thin face's sharp corner
      // more tightly than it is wide, and no cut across it unfolds it.
      throw std::invalid_argument(fmt::format(
          "panel{} {}{} would fold over {} when unfolded, even cut in three: {} ribbon turns about a face's corner "
          "more sharply than it is wide (thin faces); simplifying the mesh to fewer, evener faces ({} N, fewer than "
          "its {}) may weave it",
          plural(overlapping.size()), some, overlapping.size() > 5 ? ", ..." : "",
          overlapping.size() == 1 ? "itself" : "themselves", overlapping.size() == 1 ? "its" : "each",
          options.names(Parameter::Panels), mesh.faceCount()));
    }
    size_t pieces = 0, cut = 0;
    for (const Panel& panel : result.panels) {
      pieces += panel.pieces.size();
      cut += panel.pieces.empty() ? 0 : 1;
    }
    if (cut > 0) {
      result.warnings.push_back(fmt::format(
          "{} panel{} would overlap {} when unfolded: cut into {} more piece{}, each fastened to the next where "
          "they overlap (the steps say which)",
          cut, plural(cut), cut == 1 ? "itself" : "themselves", pieces, plural(pieces)));
    }
  }
  {
    // An offset on the scale of the edges stands the ribbons over and
    // under a crossing far apart: no longer a weave that holds together.
    double meanEdge = 0;
    for (const EdgeRegion& region : regions) meanEdge += (region.end - region.start).norm();
    meanEdge /= static_cast<double>(std::max<size_t>(1, regions.size()));
    if (options.shape.offset > kMostOffsetPerEdge * meanEdge) {
      result.warnings.push_back(fmt::format(
          "{} {:g} in stands the ribbons over and under each crossing {:g} in apart, more than {:.0f}% of the mean "
          "edge ({:.3g} in): the panels will not lie on each other; half the material's thickness is the default",
          options.names(Parameter::Offset), options.shape.offset, 2 * options.shape.offset, 200 * kMostOffsetPerEdge,
          meanEdge));
    }
  }
  if (narrowed > 0) {
    const double narrowest = *std::min_element(edgeWidths.begin(), edgeWidths.end());
    result.notes.push_back(fmt::format(
        "ribbons narrowed at {} of {} edges (to {:.2f} at the narrowest) where at {} {:g} they would pass through "
        "each other",
        narrowed, edgeWidths.size(), narrowest, options.names(Parameter::Width), options.shape.width));
  }
  if (!collisions.pairs.empty()) {
    std::string some;
    for (size_t i = 0; i < collisions.pairs.size() && i < 3; ++i) {
      const int a = edgeNumber[static_cast<size_t>(collisions.pairs[i].edgeA)];
      const int b = edgeNumber[static_cast<size_t>(collisions.pairs[i].edgeB)];
      some += fmt::format("{}{}", i ? ", " : "",
                          a == b ? fmt::format("both at edge {}", a) : fmt::format("edges {} and {}", a, b));
    }
    const size_t n = collisions.pairs.size();
    // Floored to what the option is written with (to the thousandth below 0.01, never up).
    const double digits = collisions.clearWidth >= 0.01 ? 100 : 1000;
    const double width = std::floor(collisions.clearWidth * digits) / digits;
    const std::string them = n == 1 ? "it" : "them all";
    const std::string widthName = options.names(Parameter::Width);
    // A width under the narrowest the ribbons are narrowed to leaves the
    // crossings no room for their holes: no advice (it was 0.004 on CGAL's bull).
    const std::string advice =
        width >= narrowestUsefulWidth(options.shape)
            ? fmt::format("{} {:g} or less clears {}", widthName, width, them)
            : fmt::format(
                  "{} (the faces meet at too sharp an angle): fewer and evener faces (--panels N), a smoother "
                  "mesh or a larger {} may clear {}",
                  width > 0 ? fmt::format("only {} {:g} or less clears {}, under a quarter of {:g}", widthName, width,
                                          them, options.shape.width)
                            : fmt::format("no {} tried clears {}", widthName, them),
                  options.names(Parameter::Offset), n == 1 ? "it" : "them");
    result.warnings.push_back(fmt::format("{} pair{} of ribbons pass through each other ({}{}): {}", n,
                                          n == 1 ? "" : "s", some, n > 3 ? ", ..." : "", advice));
  }
  // A fastener per hole position, through the three panels of its crossing (docs/WEAVE.md, A11).
  result.fasteners = 0;
  for (size_t e = 0; e < crossingCount; ++e) {
    if (crossings[e].panel[0] >= 0 && !glued[e]) result.fasteners += holes[e].single ? 1 : 2;
  }
  for (const Panel& panel : result.panels) result.fasteners += static_cast<int>(panel.pieces.size());
  layPanelsAlongTheirLeastBoxes(result.panels, context);
  result.steps = weaveSteps(result.panels);
  return result;
}

GrownStructure buildWeaveStructureWithRoom(PolygonMesh& mesh, const WeaveOptions& options,
                                           const core::WorkContext& context) {
  return growUntilRoom(
      mesh, [&](const PolygonMesh& grown) { return buildWeaveStructure(grown, options, context); }, context);
}

}  // namespace rotafab::geometry
