#include "geometry/WeaveStructure.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
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
#include "geometry/WeaveParts.h"
#include "geometry/WovenPanels.h"

namespace rotafab::geometry {
namespace {

std::string plural(size_t n) { return n == 1 ? "" : "s"; }

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

using weaving::CrossingHoles;
using weaving::CrossingPanels;

// The threads traced on the twisted rotation system, their ribbons, and
// the panels cut from them (IV.2, IV.3); ribbons that pass through each
// other (ch. VII's open problem) narrowed where they would, or, at a width
// asked for, left to be warned of with the width that clears them.
struct WovenRibbons {
  WeaveThreads weave;
  std::vector<EdgeRegion> regions;
  std::vector<Ribbon> ribbons;
  std::vector<double> edgeWidths;
  RibbonCollisions collisions;
  int narrowed = 0;
  std::vector<WovenPanel> woven;
  // Per edge (crossing), its two vertices in the mesh woven: where the
  // design is mended when the crossing has no room (MeshMending.h).
  std::vector<std::array<int, 2>> edgeEnds;

  // `error` with the mesh vertices of its crossings' edges (`edges`: indices of regions).
  template <typename Error>
  [[nodiscard]] Error withPlaces(Error error, const std::vector<int>& edges) const {
    error.places.clear();
    for (int e : edges) error.places.push_back(edgeEnds[static_cast<size_t>(e)]);
    return error;
  }
};

WovenRibbons ribbonsOf(const PolygonMesh& mesh, const WeaveOptions& options, const core::WorkContext& context) {
  WovenRibbons out;
  context.report({"geometry", "weaving threads", 0, 0});
  RotationSystem rs = RotationSystem::fromMesh(mesh);
  twistForWeave(rs, options.cycles, lowestFace(mesh, options.up));
  out.weave = traceThreads(rs);
  out.regions = edgeRegions(mesh, rs);
  out.edgeEnds.resize(out.regions.size());
  for (size_t e = 0; e < out.regions.size(); ++e) {
    out.edgeEnds[e] = {rs.origin(2 * static_cast<int>(e)), rs.target(2 * static_cast<int>(e))};
  }
  context.check();
  context.report({"geometry", "ribbons", 0, 0});
  if (options.narrowWhereRibbonsMeet) {
    context.report({"geometry", "ribbons that meet", 0, 0});
    ClearedRibbons cleared = narrowUntilClear(rs, out.weave, out.regions, options.shape, context);
    out.ribbons = std::move(cleared.ribbons);
    out.edgeWidths = std::move(cleared.edgeWidths);
    out.collisions = std::move(cleared.left);
    out.narrowed = cleared.narrowed;
  } else {
    out.ribbons = weaveRibbons(rs, out.weave, out.regions, options.shape);
    out.edgeWidths.assign(out.regions.size(), options.shape.width);
    context.report({"geometry", "ribbons that meet", 0, 0});
    out.collisions = ribbonCollisions(rs, out.weave, out.regions, out.ribbons, options.shape, context);
  }
  const int overlap = std::max(1, options.shape.samples / 2);
  out.woven = wovenPanels(out.ribbons, out.regions, overlap);
  context.check();
  return out;
}

// The panels numbered in assembly order (IV.4): thread by thread, each
// from its lowest crossing over; an edge takes the number of the panel over it.
struct WeaveNumbering {
  std::vector<int> order;       // panel id - 1 -> woven index
  std::vector<int> idOf;        // woven index -> panel id
  std::vector<int> edgeNumber;  // per edge region
  std::vector<int> cycleOf;     // per thread, from 1 in the order woven
};

WeaveNumbering numberInAssemblyOrder(const WovenRibbons& w, int up) {
  const std::vector<WovenPanel>& woven = w.woven;
  const std::vector<EdgeRegion>& regions = w.regions;
  WeaveNumbering n;
  std::vector<std::vector<int>> panelsOfThread(w.ribbons.size());
  for (size_t i = 0; i < woven.size(); ++i)
    panelsOfThread[static_cast<size_t>(woven[i].thread)].push_back(static_cast<int>(i));
  n.cycleOf.assign(w.ribbons.size(), 0);
  int cycle = 0;
  for (int t : threadOrder(w.weave, regions, up)) {
    auto& mine = panelsOfThread[static_cast<size_t>(t)];
    n.cycleOf[static_cast<size_t>(t)] = ++cycle;
    if (mine.empty()) continue;
    const auto lowest = std::min_element(mine.begin(), mine.end(), [&](int a, int b) {
      return regions[static_cast<size_t>(woven[static_cast<size_t>(a)].upEdge)].midpoint[up] <
             regions[static_cast<size_t>(woven[static_cast<size_t>(b)].upEdge)].midpoint[up];
    });
    std::rotate(mine.begin(), lowest, mine.end());
    n.order.insert(n.order.end(), mine.begin(), mine.end());
  }
  n.idOf.assign(woven.size(), 0);
  n.edgeNumber.assign(regions.size(), 0);
  for (size_t k = 0; k < n.order.size(); ++k) {
    n.idOf[static_cast<size_t>(n.order[k])] = static_cast<int>(k) + 1;
    n.edgeNumber[static_cast<size_t>(woven[static_cast<size_t>(n.order[k])].upEdge)] = static_cast<int>(k) + 1;
  }
  return n;
}

// Each crossing's three panels.
std::vector<CrossingPanels> crossingPanelsOf(const std::vector<WovenPanel>& woven, size_t crossingCount) {
  std::vector<CrossingPanels> crossings(crossingCount);
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
  return crossings;
}

// Whether each crossing's holes have room: those without are glued only
// when asked (--glue-narrow: a builder glues them), else the weave is
// refused there (NoRoomForHoleError, with the scale that gives every one
// room, and the crossings' edges, where make mends the design); single and
// narrow holes are warned of. Returns the crossings glued (1).
std::vector<char> judgeRoomForHoles(const std::vector<CrossingHoles>& holes,
                                    const std::vector<CrossingPanels>& crossings, const WovenRibbons& w,
                                    const std::vector<int>& edgeNumber, const WeaveOptions& options,
                                    Structure& result) {
  const double d = options.fastener;
  const size_t crossingCount = holes.size();
  std::vector<char> glued(crossingCount, 0);
  int narrow = 0, single = 0;
  double scaleNeeded = 1, narrowest = kClearance;
  int first = 0, narrowestEdge = 0;
  std::vector<double> scales;
  std::vector<int> withoutRoom;  // indices of regions
  for (size_t e = 0; e < crossingCount; ++e) {
    if (crossings[e].panel[0] < 0) continue;
    const double c = holes[e].clearance;
    if (c < kLeastClearance) {
      withoutRoom.push_back(static_cast<int>(e));
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
  const auto count = static_cast<int>(withoutRoom.size());
  if (count > 0 && options.glueCrossingsWithoutRoom) {
    for (int e : withoutRoom) {
      glued[static_cast<size_t>(e)] = 1;
      result.glued.push_back(edgeNumber[static_cast<size_t>(e)]);
    }
    std::sort(result.glued.begin(), result.glued.end());
    std::string some;
    for (size_t i = 0; i < std::min<size_t>(result.glued.size(), 5); ++i) {
      some += fmt::format("{}{}", i ? ", " : "", result.glued[i]);
    }
    result.warnings.push_back(
        fmt::format("{} crossing{} no room for a {} fastener hole {:g} diameter from its panels' outlines, so no "
                    "hole: glue {} (edge{} {}{})",
                    count, count == 1 ? " has" : "s have", options.names.unit(d, 3), kLeastClearance,
                    count == 1 ? "it" : "them", count == 1 ? "" : "s", some, result.glued.size() > 5 ? ", ..." : ""));
  } else if (count > 0) {
    std::sort(scales.begin(), scales.end(), std::greater<>());
    NoRoomForHoleError error(
        fmt::format("edge {}: its crossing has no room for two {} holes {:g} diameter from the outlines of "
                    "its three panels{}",
                    first, options.names.unit(d, 3), kLeastClearance,
                    count > 1 ? fmt::format(" (nor have {} other crossings)", count - 1) : ""),
        1, scaleNeeded, d, options.names);
    error.bands = count;
    error.scales = scales;
    throw w.withPlaces(error, withoutRoom);
  }
  if (single > 0) {
    result.warnings.push_back(
        fmt::format("{} crossing{} too small for two {} holes: one at {} centre, through its three panels; a larger {} "
                    "or a smaller {} gives {} two",
                    single, single == 1 ? " is" : "s are", options.names.unit(d, 3), single == 1 ? "its" : "each one's",
                    options.names(Parameter::Size), options.names(Parameter::Fastener), single == 1 ? "it" : "them"));
  }
  if (narrow > 0) {
    result.warnings.push_back(
        fmt::format("{} crossing{} too narrow for {} holes {} diameters from the panels' outlines, down to {:.2f} "
                    "diameters (edge {}); a larger {} or a smaller {} gives them the full clearance",
                    narrow, narrow == 1 ? " is" : "s are", options.names.unit(d, 3), kClearance, narrowest,
                    narrowestEdge, options.names(Parameter::Size), options.names(Parameter::Fastener)));
  }
  return glued;
}

// Everything a panel's own step needs, read only (the panels are made in parallel).
struct WeaveLayout {
  const WovenRibbons& w;
  const WeaveNumbering& numbering;
  const std::vector<CrossingPanels>& crossings;
  const std::vector<std::vector<Point2>>& outlines;
  const std::vector<std::vector<PanelHole>>& holesOf;
  const HersheyFont& font;
  int reach = 1;  // rows either side of a crossing a label may move to
};

// Panel k of the assembly order: its strip, holes and joins (under it at
// its up crossing, and over it and on its own thread at each end).
Panel panelOf(const WeaveLayout& layout, size_t k) {
  const size_t i = static_cast<size_t>(layout.numbering.order[k]);
  const WovenPanel& w = layout.w.woven[i];
  const std::vector<int>& idOf = layout.numbering.idOf;
  Panel panel;
  panel.id = static_cast<int>(k) + 1;
  panel.source.edge = panel.id;
  panel.source.cycle = layout.numbering.cycleOf[static_cast<size_t>(w.thread)];
  panel.outline = layout.outlines[i];
  panel.holes = layout.holesOf[i];
  panel.area = w.area;
  // A quad per row, (P_r+1, P_r, Q_r, Q_r+1): its fan from the first
  // corner is the strip's two triangles (P_r, Q_r, P_r+1), (Q_r, Q_r+1,
  // P_r+1), as they were unfolded; half the polygons of two triangles
  // (a 50,000-face weave keeps 3.6 million rows).
  panel.surface.reserve(static_cast<size_t>(std::max(0, w.rows() - 1)));
  for (size_t r = 0; r + 1 < w.railP.size(); ++r) {
    panel.surface.push_back({w.railP[r + 1], w.railP[r], w.railQ[r], w.railQ[r + 1]});
  }
  const CrossingPanels& atUp = layout.crossings[static_cast<size_t>(w.upEdge)];
  for (size_t j : {1, 2}) panel.joins.push_back({idOf[static_cast<size_t>(atUp.panel[j])], panel.id});
  for (int e : w.downEdges) {
    const CrossingPanels& atDown = layout.crossings[static_cast<size_t>(e)];
    for (size_t j : {0, 1, 2}) {
      const int other = idOf[static_cast<size_t>(atDown.panel[j])];
      if (other != panel.id) panel.joins.push_back({other, layout.numbering.edgeNumber[static_cast<size_t>(e)]});
    }
  }
  return panel;
}

// The panel's labels (IV.4, fig. 39-43): the up edge's number in the
// middle, each down edge's at its end, all reading along the thread; the
// neighbouring edge's number underlined beside the middle one
// (docs/WEAVE.md, 1.12, A12). Returns the rows the labels lie on; names
// those that do not fit in `unfitted`, and the crossings (indices of
// regions) they belong at in `unfittedAt`.
std::vector<int> labelPanel(const WeaveLayout& layout, size_t i, Panel& panel, std::vector<std::string>& unfitted,
                            std::vector<int>& unfittedAt) {
  const WovenPanel& w = layout.w.woven[i];
  const int reach = layout.reach;
  std::vector<Circle> circles;
  for (const PanelHole& hole : panel.holes) circles.push_back({hole.xy, hole.diameter / 2});
  std::vector<TextBox> taken;
  std::vector<int> labelRows;
  const auto place = [&](const std::string& label, int edge, int crossing, LabelRole role, int row, int first, int last,
                         const std::vector<Point2>& candidates) {
    const std::vector<Point2> region = w.outlineOfRows(std::max(first, 0), std::min(last, w.rows() - 1));
    const std::string text = labelText(label);
    const auto box = fitText(layout.font, text, alongThenAcross(weaving::angleAtRow(w, row)), region, panel.outline,
                             circles, taken, candidates);
    if (!box) {
      unfitted.push_back(fmt::format("{} {} on panel {}", roleName(role), label, panel.id));
      unfittedAt.push_back(crossing);
      return;
    }
    taken.push_back(*box);
    PanelLabel placed{text, edge, role, *box, labelStrokes(layout.font, label, box->origin, box->height, box->angle)};
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
      if ((weaving::centreOfRow(w, r) - centre).norm() < (weaving::centreOfRow(w, nearest) - centre).norm()) {
        nearest = r;
      }
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
    place(std::to_string(panel.id), panel.id, w.upEdge, LabelRole::Up, u, u - reach, u + reach,
          weaving::labelCandidates(w, rows));
  }
  // The neighbouring edge: the panel under this one met first turning
  // counter-clockwise about N_e from the direction this one runs.
  {
    const std::vector<Ribbon>& ribbons = layout.w.ribbons;
    const RibbonPass& over = ribbons[static_cast<size_t>(w.thread)].passes[static_cast<size_t>(w.upPass)];
    const StepRef under = layout.w.weave.down[static_cast<size_t>(w.upEdge)];
    const RibbonPass& below = ribbons[static_cast<size_t>(under.thread)].passes[static_cast<size_t>(under.step)];
    const Point3 overRuns = (over.tail[0] + over.tail[1]) - (over.head[0] + over.head[1]);
    const Point3 underRuns = (below.tail[0] + below.tail[1]) - (below.head[0] + below.head[1]);
    const bool after = overRuns.cross(underRuns).dot(layout.w.regions[static_cast<size_t>(w.upEdge)].normal) > 0;
    const CrossingPanels& atUp = layout.crossings[static_cast<size_t>(w.upEdge)];
    const int neighbour = layout.numbering.idOf[static_cast<size_t>(atUp.panel[after ? 2 : 1])];
    std::vector<int> rows = weaving::rowsFrom(w, u + 1, u + reach);
    const auto other = weaving::rowsFrom(w, u - 1, u - reach);
    rows.insert(rows.end(), other.begin(), other.end());
    place(std::to_string(neighbour), neighbour, w.upEdge, LabelRole::Neighbor, u, u - reach, u + reach,
          weaving::labelCandidates(w, rows));
  }
  for (int end = 0; end < 2; ++end) {
    const int row = w.downRows[static_cast<size_t>(end)];
    const int number = layout.numbering.edgeNumber[static_cast<size_t>(w.downEdges[static_cast<size_t>(end)])];
    // Past the holes towards the panel's end first, then towards its middle.
    const int outwards = end == 0 ? -1 : 1;
    std::vector<int> rows = weaving::rowsFrom(w, row + outwards, row + outwards * reach);
    const auto inwards = weaving::rowsFrom(w, row - outwards, row - outwards * reach);
    rows.insert(rows.end(), inwards.begin(), inwards.end());
    place(std::to_string(number), number, w.downEdges[static_cast<size_t>(end)], LabelRole::Down, row, row - reach,
          row + reach, weaving::labelCandidates(w, rows));
  }
  return labelRows;
}

// Panels that fold over themselves even cut in three (refused: nobody
// could cut and build them), labels that did not fit, and panels cut
// apart. A label that fits nowhere leaves a panel nobody can place (IV.4:
// the builders find each panel's place by its numbers), so its crossings
// have no room as a hole's do (NoRoomForHoleError::forLabels(), mended or
// refused by make); only with glue asked for is it warned of instead.
void judgePanels(const std::vector<std::vector<std::string>>& unfittedOf,
                 const std::vector<std::vector<int>>& unfittedAt, const std::vector<char>& stillFolded,
                 const std::vector<int>& upEdges, const PolygonMesh& mesh, const WovenRibbons& w,
                 const std::vector<int>& edgeNumber, const WeaveOptions& options, Structure& result) {
  std::vector<int> overlapping, edges;
  for (size_t k = 0; k < result.panels.size(); ++k) {
    if (stillFolded[k]) overlapping.push_back(result.panels[k].id), edges.push_back(upEdges[k]);
  }
  if (!overlapping.empty()) {
    std::string some;
    for (size_t i = 0; i < overlapping.size() && i < 5; ++i) some += fmt::format("{}{}", i ? ", " : "", overlapping[i]);
    // Not a panel anyone could cut and build: its ribbon folds over
    // itself, mostly where it turns about a thin face's sharp corner
    // more tightly than it is wide, and no cut across it unfolds it.
    UnfoldOverlapError error(fmt::format(
        "panel{} {}{} would fold over {} when unfolded, even cut in three: {} ribbon turns about a face's corner "
        "more sharply than it is wide (thin faces); simplifying the mesh to fewer, evener faces ({} N, fewer than "
        "its {}) may weave it",
        plural(overlapping.size()), some, overlapping.size() > 5 ? ", ..." : "",
        overlapping.size() == 1 ? "itself" : "themselves", overlapping.size() == 1 ? "its" : "each",
        options.names(Parameter::Panels), mesh.faceCount()));
    error.panels = static_cast<int>(overlapping.size());
    throw w.withPlaces(error, edges);
  }
  std::set<int> crossings;  // indices of regions
  int firstAt = -1;
  std::string first;
  for (size_t i = 0; i < unfittedAt.size(); ++i) {
    crossings.insert(unfittedAt[i].begin(), unfittedAt[i].end());
    if (firstAt < 0 && !unfittedAt[i].empty()) firstAt = unfittedAt[i].front(), first = unfittedOf[i].front();
  }
  if (!crossings.empty() && !options.glueCrossingsWithoutRoom) {
    const auto count = static_cast<int>(crossings.size());
    NoRoomForHoleError error = NoRoomForHoleError::forLabels(
        fmt::format("edge {}: label {} fits nowhere on its ribbon, even at {}{}",
                    edgeNumber[static_cast<size_t>(firstAt)], first, options.names.unit(kSmallestLabel, 3),
                    count > 1 ? fmt::format(" (nor do labels at {} other crossings)", count - 1) : ""),
        1, options.names);
    error.bands = count;
    throw w.withPlaces(error, std::vector<int>(crossings.begin(), crossings.end()));
  }
  if (auto warning = unetchedLabelsWarning(unfittedOf, "ribbon", options.names.unit))
    result.warnings.push_back(std::move(*warning));
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

// What the ribbons' shape left to say: an offset that stands them apart,
// ribbons narrowed, and ribbons that still pass through each other.
void judgeRibbons(const WovenRibbons& w, const std::vector<int>& edgeNumber, const WeaveOptions& options,
                  Structure& result) {
  {
    // An offset on the scale of the edges stands the ribbons over and
    // under a crossing far apart: no longer a weave that holds together.
    double meanEdge = 0;
    for (const EdgeRegion& region : w.regions) meanEdge += (region.end - region.start).norm();
    meanEdge /= static_cast<double>(std::max<size_t>(1, w.regions.size()));
    if (options.shape.offset > kMostOffsetPerEdge * meanEdge) {
      result.warnings.push_back(fmt::format(
          "{} {} stands the ribbons over and under each crossing {} apart, more than {:.0f}% of the mean "
          "edge ({}): the panels will not lie on each other; half the material's thickness is the default",
          options.names(Parameter::Offset), options.names.unit(options.shape.offset, 3),
          options.names.unit(2 * options.shape.offset, 3), 200 * kMostOffsetPerEdge, options.names.unit(meanEdge, 3)));
    }
  }
  if (w.narrowed > 0) {
    const double narrowest = *std::min_element(w.edgeWidths.begin(), w.edgeWidths.end());
    result.notes.push_back(fmt::format(
        "ribbons narrowed at {} of {} edges (to {:.2f} at the narrowest) where at {} {:g} they would pass through "
        "each other",
        w.narrowed, w.edgeWidths.size(), narrowest, options.names(Parameter::Width), options.shape.width));
  }
  const RibbonCollisions& collisions = w.collisions;
  if (collisions.pairs.empty()) return;
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
  result.warnings.push_back(fmt::format("{} pair{} of ribbons pass through each other ({}{}): {}", n, n == 1 ? "" : "s",
                                        some, n > 3 ? ", ..." : "", advice));
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
  const WovenRibbons w = ribbonsOf(mesh, options, context);
  const std::vector<WovenPanel>& woven = w.woven;
  const WeaveNumbering numbering = numberInAssemblyOrder(w, options.up);
  const size_t crossingCount = w.regions.size();
  const std::vector<CrossingPanels> crossings = crossingPanelsOf(woven, crossingCount);
  std::vector<std::vector<Point2>> outlines(woven.size());
  context.parallelFor(woven.size(), [&](size_t i) { outlines[i] = woven[i].outline(); });

  Structure result;
  result.kind = StructureKind::Weave;
  result.edges = static_cast<int>(woven.size());
  const double d = options.fastener;
  context.report({"geometry", "crossing holes", 0, static_cast<size_t>(result.edges)});
  std::vector<CrossingHoles> holes(crossingCount);
  context.parallelFor(crossingCount, [&](size_t e) {
    if (crossings[e].panel[0] < 0) return;  // untwisted: no crossing
    RibbonShape shape = options.shape;
    shape.width = w.edgeWidths[e];
    holes[e] = weaving::placeCrossingHoles(w.regions[e], crossings[e], woven, outlines, shape, d);
  });
  const std::vector<char> glued = judgeRoomForHoles(holes, crossings, w, numbering.edgeNumber, options, result);
  context.check();

  // Per panel, its holes: two (or one) at each of its three crossings.
  std::vector<std::vector<PanelHole>> holesOf(woven.size());
  std::vector<std::vector<int>> holeRowsOf(woven.size());
  for (size_t e = 0; e < crossingCount; ++e) {
    if (crossings[e].panel[0] < 0 || glued[e]) continue;
    for (size_t k = 0; k < 3; ++k) {
      for (size_t h = 0; h < (holes[e].single ? 1U : 2U); ++h) {
        const int edge = numbering.edgeNumber[e];
        holesOf[static_cast<size_t>(crossings[e].panel[k])].push_back({edge, holes[e].flat[k][h], d});
        holeRowsOf[static_cast<size_t>(crossings[e].panel[k])].push_back(holes[e].rows[k][h]);
      }
    }
  }

  context.report({"geometry", "labels", 0, woven.size()});
  const HersheyFont& font = HersheyFont::simplex();
  const WeaveLayout layout{w, numbering, crossings, outlines, holesOf, font, std::max(1, options.shape.samples / 2)};
  result.panels.resize(woven.size());
  std::vector<std::vector<std::string>> unfittedOf(woven.size());
  std::vector<std::vector<int>> unfittedAt(woven.size());  // each label's crossing
  std::vector<char> stillFolded(woven.size(), 0);          // per panel: crosses itself even cut
  std::vector<int> upEdges(woven.size());                  // per panel: its own edge (an index of regions)
  context.parallelFor(numbering.order.size(), [&](size_t k) {
    const size_t i = static_cast<size_t>(numbering.order[k]);
    upEdges[k] = woven[i].upEdge;
    Panel panel = panelOf(layout, k);
    const std::vector<int> labelRows = labelPanel(layout, i, panel, unfittedOf[i], unfittedAt[i]);
    if (core::crossesItself(panel.outline)) {
      weaving::cutApart(woven[i], panel, holeRowsOf[i], labelRows, d, font, unfittedOf[i]);
      // (A piece's name belongs with the panel's own crossing.)
      unfittedAt[i].resize(unfittedOf[i].size(), woven[i].upEdge);
      stillFolded[k] = core::crossesItself(panel.outline) ? 1 : 0;
    }
    result.panels[k] = std::move(panel);
  });
  judgePanels(unfittedOf, unfittedAt, stillFolded, upEdges, mesh, w, numbering.edgeNumber, options, result);
  judgeRibbons(w, numbering.edgeNumber, options, result);
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
