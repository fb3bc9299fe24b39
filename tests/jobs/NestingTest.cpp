// Nesting (issue 3, items 2-3): every layout is checked with exact polygon
// geometry — no two parts nearer than the spacing, all inside the area — on
// random concave parts, and the order modes keep their promises.

#include "jobs/Nesting.h"
#include "jobs/RowLayout.h"

#include "support/NestingParts.h"
#include "support/TestContext.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <set>

namespace rotafab::jobs {
namespace {

using test::randomParts;
using test::star;
using test::wavyStrip;

void expectValid(const std::vector<NestingPart>& parts, const NestingResult& result, const NestingOptions& options) {
  EXPECT_EQ(layoutProblems(parts, result, options), std::vector<std::string>{});
  ASSERT_EQ(result.placements.size(), parts.size());
  std::set<int> placed;
  for (const auto& p : result.placements) {
    placed.insert(p.part);
    EXPECT_GE(p.sheet, 1);
    EXPECT_LE(p.sheet, result.sheets);
  }
  EXPECT_EQ(placed.size(), parts.size()) << "every part exactly once";
  double area = 0;
  for (const auto& part : parts) area += std::abs(polygonArea(part.outline));
  if (!options.strip) {
    EXPECT_GE(result.sheets, std::ceil(area / (options.width * options.height) - 1e-9));
  }
}

void expectSameLayout(const NestingResult& a, const NestingResult& b) {
  ASSERT_EQ(a.placements.size(), b.placements.size());
  for (size_t i = 0; i < a.placements.size(); ++i) {
    EXPECT_EQ(a.placements[i].part, b.placements[i].part);
    EXPECT_EQ(a.placements[i].x, b.placements[i].x);
    EXPECT_EQ(a.placements[i].y, b.placements[i].y);
    EXPECT_EQ(a.placements[i].rotation, b.placements[i].rotation);
  }
}

TEST(Nesting, RandomConcavePartsNeverOverlapAndStayInside) {
  for (unsigned seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const auto parts = randomParts(seed, 16);
    NestingOptions options;
    options.width = 31.5;
    options.height = 17.5;
    options.spacing = 0.0625;
    options.seconds = 0.2;
    options.seed = seed;
    expectValid(parts, nest(parts, options, test::context()), options);
  }
}

TEST(Nesting, StripModeKeepsTheHeightAndPacksTheLength) {
  const auto parts = randomParts(7, 14);
  NestingOptions options;
  options.strip = true;
  options.height = 10;
  options.spacing = 0;
  options.seconds = 0.2;
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  EXPECT_EQ(result.sheets, 1);
  double area = 0;
  for (const auto& part : parts) area += std::abs(polygonArea(part.outline));
  EXPECT_GT(result.stripLength, area / options.height) << "no denser than solid";
}

// One search with a cap on layouts (the same run on any machine), 1/16 in
// spacing; the layout is checked exactly and its progress is kept.
NestingResult cappedRun(const std::vector<NestingPart>& parts, NestingOptions options, int evaluations,
                        std::vector<core::Progress>& progress) {
  options.spacing = 0.0625;
  options.seconds = 600;
  options.evaluations = evaluations;
  options.threads = 1;
  test::TestContext context;
  NestingResult result = nest(parts, options, context);
  progress = context.progress();
  expectValid(parts, result, options);
  return result;
}

TEST(Nesting, StripCompactionShortensTheStripAndKeepsTheSpacing) {
  // After the sequence search, the compaction shortens the strip by letting
  // parts overlap and moving them apart again; it reports each shorter strip
  // it finds, and the shortest is kept, checked exactly. (On this instance,
  // with this cap on layouts and one search, it finds one: the cap makes the
  // run the same on any machine. Big stars with long strips in a strip 10
  // high are tight: on most such instances the cap's 850 moves are too few.)
  const auto parts = randomParts(13, 10);
  NestingOptions options;
  options.strip = true;
  options.height = 10;
  std::vector<core::Progress> progress;
  const NestingResult result = cappedRun(parts, options, 1000, progress);
  // Compacting, the strip's length: the shortest strip reported is the one kept.
  double shortest = std::numeric_limits<double>::max();
  for (const core::Progress& p : progress) {
    if (p.step == "compacting") shortest = std::min(shortest, p.length);
  }
  ASSERT_LT(shortest, std::numeric_limits<double>::max()) << "the compaction never found a shorter strip";
  EXPECT_NEAR(result.stripLength, shortest, 0.005);
}

TEST(Nesting, BedCompactionShortensTheLastSheet) {
  // On beds, the compaction lays the beds side by side and takes slices out
  // of the last one: its parts move onto the earlier beds. It reports each
  // better layout (sheets, length of the last sheet), and the best is kept,
  // inside every bed's margins and with the spacing, checked exactly.
  const auto parts = randomParts(7, 24);
  NestingOptions options;
  options.width = 16;
  options.height = 10;
  std::vector<core::Progress> progress;
  const NestingResult result = cappedRun(parts, options, 200, progress);
  // Compacting: sheets and the last sheet's length; progress only reports
  // layouts better than the first.
  std::optional<std::pair<int, double>> best;
  for (const core::Progress& p : progress) {
    if (p.step != "compacting") continue;
    ASSERT_GT(p.sheets, 0);
    best = std::min(best.value_or(std::pair{p.sheets, p.length}), std::pair{p.sheets, p.length});
  }
  ASSERT_TRUE(best.has_value()) << "the compaction never found a better layout";
  EXPECT_EQ(result.sheets, best->first);
  for (int sheet = 1; sheet <= result.sheets; ++sheet) {
    EXPECT_TRUE(std::any_of(result.placements.begin(), result.placements.end(),
                            [&](const PartPlacement& p) { return p.sheet == sheet; }))
        << "sheet " << sheet << " is empty";
  }
  double lastLength = 0;
  for (const auto& placement : result.placements) {
    if (placement.sheet != result.sheets) continue;
    for (const Point2& p : placedOutline(parts[placement.part], placement)) lastLength = std::max(lastLength, p.x());
  }
  EXPECT_NEAR(lastLength, best->second, 0.005);
}

// Once a layout has the fewest sheets the parts' area allows, the search
// stops: a few small parts on one bed do not spend the whole budget.
TEST(Nesting, TheSearchStopsAtTheAreaBound) {
  const auto parts = randomParts(6, 3);
  NestingOptions options;
  options.width = 30;
  options.height = 17;
  options.seconds = 60;  // (never reached: the first layout is on one sheet)
  ASSERT_EQ(sheetsTheAreaNeeds(parts, options), 1);
  options.threads = 2;
  const NestingResult result = nest(parts, options, test::context());
  EXPECT_EQ(result.sheets, 1);
  EXPECT_EQ(result.evaluations, 2) << "only the first layout of each search";
  expectValid(parts, result, options);
}

// The budget holds for the first layout too: with none, the parts are
// laid out in rows by their boxes, and said so.
TEST(Nesting, NoBudgetLaysThePartsOutInRows) {
  const auto parts = randomParts(11, 12);
  NestingOptions options;
  options.seconds = 0;
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  EXPECT_EQ(result.inRows, static_cast<int>(parts.size()));
  expectSameLayout(result, rowLayout(parts, options));
  EXPECT_EQ(inRowsNote(result).rfind("the time budget ran out before the first layout began: the 12 parts", 0), 0u)
      << inRowsNote(result);
}

// When the budget runs out in the first layout, the parts it placed stay
// where they are and the rest follow in rows, on sheets of their own.
TEST(Nesting, ABudgetThatRunsOutInTheFirstLayoutKeepsItsPartsAndRowsTheRest) {
  const auto parts = randomParts(23, 6000);
  NestingOptions options;
  options.seconds = 1;  // (6000 parts take several seconds; the first few hundred, well under one)
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  ASSERT_EQ(result.placements.size(), parts.size());
  std::vector<int> times(parts.size(), 0);
  for (const PartPlacement& p : result.placements) ++times.at(static_cast<size_t>(p.part));
  EXPECT_EQ(std::count(times.begin(), times.end(), 1), static_cast<long>(parts.size())) << "each part once";
  EXPECT_GT(result.inRows, 0);
  EXPECT_LT(result.inRows, static_cast<int>(parts.size()));
  const std::string note = inRowsNote(result);
  EXPECT_NE(note.find(" of 6000 parts: the other " + std::to_string(result.inRows) + " are laid out in rows"),
            std::string::npos)
      << note;
  std::vector<int> perSheet(static_cast<size_t>(result.sheets) + 1, 0);
  for (const PartPlacement& p : result.placements) ++perSheet.at(static_cast<size_t>(p.sheet));
  for (int s = 1; s <= result.sheets; ++s) EXPECT_GT(perSheet[static_cast<size_t>(s)], 0) << "sheet " << s;
  // In cutting order: the first layout's sheets, then the rows'.
  for (size_t i = 1; i < result.placements.size(); ++i) {
    EXPECT_LE(result.placements[i - 1].sheet, result.placements[i].sheet);
  }
}

TEST(Nesting, SameSeedAndEvaluationsSameLayoutWhateverTheClock) {
  const auto parts = randomParts(12, 10);
  NestingOptions options;
  options.width = 15, options.height = 6;  // small beds: layouts above the area bound, so that the search goes on
  options.seconds = 600;                   // never the limit here
  options.evaluations = 25;
  options.seed = 9;
  options.threads = 2;
  const NestingResult a = nest(parts, options, test::context()), b = nest(parts, options, test::context());
  EXPECT_EQ(a.evaluations, 50) << "two searches of 25 layouts";
  expectSameLayout(a, b);
}

TEST(Nesting, SideBySideSearchesAreNeverWorseThanOne) {
  // The first of several searches follows the course of a lone search with
  // the same seed, so the best of them can only be as good or better.
  for (const bool strip : {false, true}) {
    SCOPED_TRACE(strip ? "strip" : "bins");
    const auto parts = randomParts(13, 14);
    NestingOptions options;
    options.strip = strip;
    options.width = 20;
    options.height = 10;
    options.seconds = 600;
    options.evaluations = 30;
    options.threads = 1;
    const NestingResult alone = nest(parts, options, test::context());
    options.threads = 3;
    const NestingResult together = nest(parts, options, test::context());
    expectValid(parts, together, options);
    EXPECT_LE(together.sheets, alone.sheets);
    if (strip) {
      EXPECT_LE(together.stripLength, alone.stripLength);
    }
    EXPECT_GT(together.evaluations, alone.evaluations) << "the layouts of all three searches are counted";
  }
}

TEST(Nesting, StrictOrderPutsAContiguousRunOnEachSheet) {
  const auto parts = randomParts(5, 20);
  NestingOptions options;
  options.order = OrderMode::Strict;
  options.width = 15;
  options.height = 10;
  options.evaluations = 1;  // the first layout only
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  // In cutting order the assembly order never goes down.
  for (size_t i = 1; i < result.placements.size(); ++i) {
    EXPECT_EQ(parts[result.placements[i].part].order, parts[result.placements[i - 1].part].order + 1);
  }
}

// Parts that may be cut at any angle, on a job too large for no-fit
// polygons, are tried at even turns besides quarter turns (star-shaped
// panels interlock at other angles); the turned shapes are the first's
// turned and rounded to the grid, and the layout must still keep every
// outline on the bed and the spacing between them, exactly.
TEST(Nesting, PartsThatTurnFreelyKeepTheSpacingAtEveryTurn) {
  EXPECT_EQ(anyAngleTurns(40), 4) << "no-fit polygons cost the square of the turns";
  EXPECT_EQ(anyAngleTurns(3660), 24);
  EXPECT_EQ(anyAngleTurns(5166), 16);
  EXPECT_EQ(anyAngleTurns(75000), 4);
  std::mt19937 random(11);
  std::vector<NestingPart> parts;
  for (int i = 0; i < 450; ++i) {
    parts.push_back({"panel " + std::to_string(i + 1), star(random, 5 + i % 3, 0.6 + (i % 5) / 10.0)});
    parts.back().order = i;
  }
  NestingOptions options;
  options.order = OrderMode::Kits;
  options.anyAngle = true;
  options.evaluations = 1;  // the first layout only, on any machine
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  EXPECT_TRUE(inKits(parts, result));
  const double step = 360.0 / anyAngleTurns(parts.size());
  int unquartered = 0;
  for (const PartPlacement& p : result.placements) {
    EXPECT_NEAR(p.rotation / step, std::round(p.rotation / step), 1e-9) << p.rotation;
    unquartered += quarterTurns(p.rotation) < 0;
  }
  EXPECT_GT(unquartered, 0) << "no part turned other than by quarter turns";
  options.anyAngle = false;
  for (const PartPlacement& p : nest(parts, options, test::context()).placements) {
    EXPECT_GE(quarterTurns(p.rotation), 0) << p.rotation;
  }
}

TEST(Nesting, WindowOrderMovesNoPartFartherThanTheWindow) {
  const auto parts = randomParts(6, 20);
  NestingOptions options;
  options.order = OrderMode::Window;
  options.window = 4;
  options.width = 15;
  options.height = 10;
  options.seconds = 0.3;
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  for (size_t i = 0; i < result.placements.size(); ++i) {
    EXPECT_LE(std::abs(parts[result.placements[i].part].order - static_cast<int>(i)), options.window)
        << parts[result.placements[i].part].name << " cut at " << i;
  }
}

TEST(Nesting, PartLargerThanTheBedIsRefusedByName) {
  std::vector<NestingPart> parts = randomParts(8, 3);
  parts[1].name = "panel 42";
  parts[1].outline = {{0, 0}, {40, 0}, {40, 1}, {0, 1}};
  NestingOptions options;
  try {
    nest(parts, options, test::context());
    FAIL() << "accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("panel 42 (40 x 1) does not fit the usable area of 31.5 x 17.5", 0), 0u)
        << error.what();
  }
}

TEST(Nesting, BedSizedPartFillsOneSheet) {
  std::vector<NestingPart> parts(1);
  parts[0].name = "board";
  parts[0].outline = {{0, 0}, {31.5, 0}, {31.5, 17.5}, {0, 17.5}};
  NestingOptions options;
  const NestingResult result = nest(parts, options, test::context());
  expectValid(parts, result, options);
  EXPECT_EQ(result.sheets, 1);
}

TEST(Nesting, AwkwardOutlinesAreNestedExactly) {
  // Outlines as instance files and unfoldings give them: repeated points,
  // straight corners, needles, bow ties (self-crossing), slivers, and
  // coordinates far from the origin. Each is nested with the rest, or the
  // whole call is refused naming one part; never overlapping parts.
  std::mt19937 random(99);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 6; ++trial) {
    SCOPED_TRACE(trial);
    std::vector<NestingPart> parts = randomParts(100 + trial, 6);
    const auto add = [&](std::string name, Polygon2 outline) {
      NestingPart part;
      part.name = std::move(name);
      part.outline = std::move(outline);
      part.order = static_cast<int>(parts.size());
      parts.push_back(std::move(part));
    };
    const double s = 0.5 + 2 * unit(random);
    add("repeated points", {{0, 0}, {0, 0}, {s, 0}, {s, 0}, {s, s}, {0, s}, {0, s}});
    add("straight corners", {{0, 0}, {s / 2, 0}, {s, 0}, {s, s / 2}, {s, s}, {0, s}});
    add("needle", {{0, 0}, {s, 0}, {s, s}, {s / 2, s}, {s / 2, 3 * s}, {s / 2, s}, {0, s}});
    // Lopsided, so that its signed area is not zero; only in the last trial,
    // since a refusal stops the whole call.
    if (trial == 5) add("bow tie", {{0, 0}, {s, s}, {s, 0}, {0, 2 * s}});
    add("sliver", {{0, 0}, {3 * s, 0}, {3 * s, 0.001}});
    add("far away", {{1000, 1000}, {1000 + s, 1000}, {1000 + s, 1000 + s / 3}, {1000, 1000 + s}});
    NestingOptions options;
    options.evaluations = 20;
    options.seconds = 600;
    options.strip = trial % 2 == 1;
    options.height = options.strip ? 8 : 17.5;
    try {
      expectValid(parts, nest(parts, options, test::context()), options);
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      const bool named = std::any_of(parts.begin(), parts.end(),
                                     [&](const NestingPart& part) { return message.rfind(part.name, 0) == 0; });
      EXPECT_TRUE(named) << message;
    }
  }
}

}  // namespace
}  // namespace rotafab::jobs

namespace rotafab::jobs {
namespace {

// The quick layout (`make --layout rows`): exact checks as for nest(), the
// cutting order is the assembly order, and an oversized part is named.
TEST(RowLayout, PartsInAssemblyOrderNeverOverlapAndStayInside) {
  auto parts = randomParts(11, 60);
  std::mt19937 random(3);
  std::vector<int> orders(parts.size());
  std::iota(orders.begin(), orders.end(), 0);
  std::shuffle(orders.begin(), orders.end(), random);
  for (size_t i = 0; i < parts.size(); ++i) parts[i].order = orders[i];
  NestingOptions options;
  options.width = 15;
  options.height = 10;
  const NestingResult result = rowLayout(parts, options);
  expectValid(parts, result, options);
  EXPECT_GT(result.sheets, 1);
  for (size_t i = 0; i < result.placements.size(); ++i) {
    EXPECT_EQ(parts[result.placements[i].part].order, static_cast<int>(i));
    if (i > 0) {
      EXPECT_GE(result.placements[i].sheet, result.placements[i - 1].sheet);
    }
  }
  parts[7].outline = {{0, 0}, {16, 0}, {16, 11}, {0, 11}};
  parts[7].name = "panel 8";
  try {
    rowLayout(parts, options);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("panel 8 does not fit the usable area of 15 x 10", 0), 0u)
        << error.what();
  }
}

}  // namespace
}  // namespace rotafab::jobs
