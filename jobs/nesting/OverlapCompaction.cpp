#include "jobs/nesting/OverlapCompaction.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace rotafab::jobs::nesting {
namespace {

// The sampled moves (sampledMove), with sparrow's settings: places drawn
// near the part and anywhere, how many of the best are refined, and how far
// apart (a share of the part's smaller side) two must be to count as two.
constexpr int kNearSamples = 25, kFarSamples = 50;
constexpr size_t kDescents = 3;
constexpr double kDistinctShare = 0.05;
// The separation (separate): rounds without progress before a strike,
// strikes before it gives up, how fast the weight of a pair that no longer
// overlaps fades back to 1, and the most a weight can grow to.
constexpr int kStaleRounds = 50, kStrikes = 3;
constexpr double kWeightFade = 0.95, kHeaviest = 1e9;
// The overlap proxy (proxy): poles that reach into each other by less than
// this share of the larger shape's diameter (or are apart) count by a
// decaying amount instead of their depth.
constexpr double kDecayShare = 0.01;
constexpr double kNoLimit = std::numeric_limits<double>::max();
// Strip compaction: the first shortening (2%), the least (0.1%), and tries
// per shortening before it is halved (docs/PERFORMANCE-LOG.md,
// "ESICUP, strip mode, 60 s per instance").
constexpr double kFirstShrink = 0.02, kLeastShrink = 0.001;
constexpr int kTriesPerShrink = 5;

// How much two colliding shapes overlap (sparrow's quantification): over
// every pair of poles, how deep they reach into each other times the
// smaller radius; pairs apart or barely in still count a little,
// decaying with the distance, so that a collision the poles do not reach
// still has a way out. The square root, scaled by the shapes' sizes,
// keeps shallow and deep collisions comparable.
double proxy(const Shape& sa, IntPoint atA, const Shape& sb, IntPoint atB) {
  const double epsilon = kDecayShare * std::max(sa.diameter, sb.diameter);
  double sum = 0;
  for (const Shape::Pole& a : sa.poles) {
    const double ax = static_cast<double>(a.centre.X + atA.X), ay = static_cast<double>(a.centre.Y + atA.Y);
    for (const Shape::Pole& b : sb.poles) {
      const double dx = ax - static_cast<double>(b.centre.X + atB.X), dy = ay - static_cast<double>(b.centre.Y + atB.Y);
      const double depth = a.radius + b.radius - std::sqrt(dx * dx + dy * dy);
      const double weighed = depth >= epsilon ? depth : epsilon * epsilon / (2 * epsilon - depth);
      sum += weighed * std::min(a.radius, b.radius);
    }
  }
  return std::sqrt(sum + epsilon * epsilon) * std::sqrt(sa.size * sb.size);
}

// A place and rotation for a sampled move, and its weighted overlap.
struct Sample {
  int shape;
  IntPoint at;
  double score;
};

}  // namespace

NestingResult OverlapCompaction::compact(std::vector<PlacedShape> layout, std::mt19937& random,
                                         const std::function<bool()>& goOn, int& moves,
                                         const std::function<void(int, double)>& shorter) const {
  std::vector<PlacedShape> best = std::move(layout);
  cInt bestLength = lengthOf(best);
  double shrink = kFirstShrink;
  int failures = 0;
  while (goOn()) {
    // Down to the least shortening: start again from the first, at other
    // places, after a disruption (as sparrow does): two parts of different
    // shapes trade places, and the layout is kept if they can be moved
    // apart at the same length.
    if (shrink < kLeastShrink) {
      shrink = kFirstShrink;
      if (best.size() > 1) {
        std::vector<PlacedShape> trial = best;
        const size_t a = random() % trial.size(), b = random() % trial.size();
        if (a != b &&
            shapes_.classOf(trial[a].part, trial[a].shape) != shapes_.classOf(trial[b].part, trial[b].shape)) {
          const IntPoint ca = centreOf(trial[a]), cb = centreOf(trial[b]);
          const auto lanes = lanesUpTo(bestLength);
          if (moveInto(trial[a], cb, lanes) && moveInto(trial[b], ca, lanes) &&
              separate(trial, lanes, random, goOn, moves)) {
            best = std::move(trial);
            bestLength = lengthOf(best);
          }
        }
      }
    }
    // In the strip, a share of its length; on beds, of a bed's, so that
    // the last bed empties in steps of the same size however full it is.
    const cInt lastStart = laneStartOf(bestLength);
    const cInt cut = std::max<cInt>(
        1, static_cast<cInt>(static_cast<double>(shapes_.options().strip ? bestLength : shapes_.width()) * shrink));
    cInt target = bestLength - cut;
    if (target <= lastStart) {
      if (lastStart == 0) break;                               // one bed, or the strip, as short as a part
      target = lastStart - shapes_.pitch() + shapes_.width();  // the last bed empties: the one before ends at its edge
    }
    // Take a slice out at a random place (as sparrow does): the parts right
    // of it move left, so the overlaps to resolve are somewhere else at
    // every try, not always at the end.
    const cInt at = std::uniform_int_distribution<cInt>(lastStart, bestLength)(random);
    const auto lanes = lanesUpTo(target);
    std::vector<PlacedShape> trial = best;
    bool fits = true;
    for (PlacedShape& s : trial) {
      if (centreOf(s).X > at) s.at.X -= cut;
      fits = fits && moveInto(s, centreOf(s), lanes);
    }
    if (!fits) break;  // a part is as long as the strip
    if (separate(trial, lanes, random, goOn, moves)) {
      best = std::move(trial);
      bestLength = lengthOf(best);
      failures = 0;
      shorter(bedsUsed(best), (bestLength - laneStartOf(bestLength)) / kScale);
    } else if (++failures == kTriesPerShrink) {
      shrink /= 2;
      failures = 0;
    }
  }
  // Back from the row of beds to each bed's own coordinates, in cutting
  // order: bed by bed, each in the order of the layout.
  // A bed in the middle that the moves emptied is left out.
  std::vector<std::pair<int, PlacedShape>> placed;
  for (PlacedShape s : best) {
    const int sheet = sheetOf(shapes_.rightOf(s));
    s.at.X -= sheet * shapes_.pitch();
    placed.emplace_back(sheet, s);
  }
  std::stable_sort(placed.begin(), placed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  int sheets = 0;
  for (size_t i = 0; i < placed.size(); ++i) {
    const bool newBed = i == 0 || placed[i].first != placed[i - 1].first;
    if (newBed) ++sheets;
    placed[i].first = sheets - 1;
  }
  return shapes_.resultOf(placed, std::max(sheets, 1));
}

bool OverlapCompaction::insert(std::vector<PlacedShape>& bed, const PlacedShape& incoming, std::mt19937& random,
                               const std::function<bool()>& goOn, int& moves) const {
  const Lanes lanes{{0, shapes_.width()}};
  std::vector<PlacedShape> trial = bed;
  trial.push_back(incoming);
  const IntPoint centre{std::uniform_int_distribution<cInt>(0, shapes_.width())(random),
                        std::uniform_int_distribution<cInt>(0, shapes_.height())(random)};
  if (!moveInto(trial.back(), centre, lanes)) return false;
  const std::vector<double> weights(trial.size() * trial.size(), 1.0);
  sampledMove(trial, trial.size() - 1, lanes, weights, random);
  ++moves;
  if (!separate(trial, lanes, random, goOn, moves)) return false;
  bed = std::move(trial);
  return true;
}

int OverlapCompaction::bedsUsed(const std::vector<PlacedShape>& layout) const {
  std::vector<int> beds;
  for (const PlacedShape& s : layout) beds.push_back(sheetOf(shapes_.rightOf(s)));
  std::sort(beds.begin(), beds.end());
  return static_cast<int>(std::unique(beds.begin(), beds.end()) - beds.begin());
}
cInt OverlapCompaction::lengthOf(const std::vector<PlacedShape>& layout) const {
  cInt length = 0;
  for (const PlacedShape& s : layout) length = std::max(length, shapes_.rightOf(s));
  return length;
}

OverlapCompaction::Lanes OverlapCompaction::lanesUpTo(cInt length) const {
  if (shapes_.options().strip) return {{0, length}};
  Lanes lanes;
  for (cInt start = 0; start < length; start += shapes_.pitch())
    lanes.emplace_back(start, std::min(start + shapes_.width(), length));
  return lanes;
}
cInt OverlapCompaction::laneStartOf(cInt right) const {
  return shapes_.options().strip ? 0 : (std::max<cInt>(right, 1) - 1) / shapes_.pitch() * shapes_.pitch();
}
int OverlapCompaction::sheetOf(cInt right) const {
  return shapes_.options().strip ? 0 : static_cast<int>(laneStartOf(right) / shapes_.pitch());
}

IntPoint OverlapCompaction::centreOf(const PlacedShape& p) const {
  const Shape& shape = shapes_.at(p.part, p.shape);
  return {p.at.X + (shape.minX + shape.maxX) / 2, p.at.Y + (shape.minY + shape.maxY) / 2};
}

// Puts `p`'s box centre at `centre`, or as near as its lane allows: the
// last lane that starts left of `centre`, or the first before it that is
// long enough for the part, in its rotation or else in the first other
// that fits. False when none is.
bool OverlapCompaction::moveInto(PlacedShape& p, IntPoint centre, const Lanes& lanes) const {
  size_t lane = 0;
  while (lane + 1 < lanes.size() && lanes[lane + 1].first <= centre.X) ++lane;
  for (size_t l = lane + 1; l-- > 0;) {
    const auto [from, to] = lanes[l];
    for (int k = -1; k < static_cast<int>(shapes_.of(p.part).size()); ++k) {
      const int tried = k < 0 ? p.shape : k;
      const Shape& shape = shapes_.at(p.part, tried);
      if (to - from < shape.maxX - shape.minX || shapes_.height() < shape.maxY - shape.minY) continue;
      p.shape = tried;
      p.at.X = std::clamp(centre.X - (shape.minX + shape.maxX) / 2, from - shape.minX, to - shape.maxX);
      p.at.Y = std::clamp(centre.Y - (shape.minY + shape.maxY) / 2, -shape.minY, shapes_.height() - shape.maxY);
      return true;
    }
  }
  return false;
}

// Moves the parts of `layout` (on the lanes) apart by guided local search,
// as sparrow's separator does: every round, each overlapping part moves
// to where its weighted overlap is least (sampledMove), and the pairs
// still overlapping weigh more, the deeper the more (x1.2 to x2), while
// the others fade back towards 1. The layout of least overlap so far is
// kept. A round that does not beat it counts towards kStaleRounds, one
// that beats it by 2% starts the count again; when the count is full,
// the moves start again from that layout (a strike, the weights kept).
// After kStrikes strikes in a row, each ending less than 2% below where
// it began, the separation fails (false), as it does when the budget runs
// out. True when nothing overlaps, checked exactly (apart()).
bool OverlapCompaction::separate(std::vector<PlacedShape>& layout, const Lanes& lanes, std::mt19937& random,
                                 const std::function<bool()>& goOn, int& moves) const {
  const size_t n = layout.size();
  std::vector<double> weights(n * n, 1.0);
  // Whether each pair overlaps, kept from round to round: only the pairs
  // of a part that moved are checked again.
  std::vector<char> overlaps(n * n, 0), moved(n, 1);
  double leastLoss = kNoLimit, strikeLoss = kNoLimit;
  std::vector<PlacedShape> leastLayout;
  int stale = 0, strikes = 0;
  while (goOn()) {
    std::vector<std::pair<size_t, size_t>> pairs;
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) {
        if (moved[i] || moved[j]) overlaps[i * n + j] = colliding(layout[i], layout[j]);
        if (overlaps[i * n + j]) pairs.emplace_back(i, j);
      }
    }
    std::fill(moved.begin(), moved.end(), 0);
    if (pairs.empty()) return apart(layout);
    std::vector<double> depth;
    for (const auto& [i, j] : pairs) {
      const Shape& a = shapes_.of(layout[i]);
      const Shape& b = shapes_.of(layout[j]);
      depth.push_back(proxy(a, layout[i].at, b, layout[j].at));
    }
    const double loss = std::accumulate(depth.begin(), depth.end(), 0.0);
    if (leastLoss == kNoLimit) strikeLoss = loss;
    if (loss < leastLoss) {
      if (loss < 0.98 * leastLoss) stale = 0;
      leastLoss = loss, leastLayout = layout;
    } else if (++stale == kStaleRounds) {
      strikes = strikeLoss * 0.98 <= leastLoss ? strikes + 1 : 0;
      if (strikes == kStrikes) return false;
      strikeLoss = leastLoss, stale = 0;
      layout = leastLayout;
      std::fill(moved.begin(), moved.end(), 1);
      continue;
    }
    std::vector<char> grows(n * n, 0);
    const double deepest = *std::max_element(depth.begin(), depth.end());
    for (size_t p = 0; p < pairs.size(); ++p) {
      const auto [i, j] = pairs[p];
      const double grown = std::min(kHeaviest, weights[i * n + j] * (1.2 + 0.8 * depth[p] / deepest));
      weights[i * n + j] = weights[j * n + i] = grown;
      grows[i * n + j] = grows[j * n + i] = 1;
    }
    for (size_t k = 0; k < n * n; ++k) {
      if (!grows[k]) weights[k] = std::max(1.0, weights[k] * kWeightFade);
    }
    std::vector<size_t> overlapped;
    for (const auto& [i, j] : pairs) overlapped.push_back(i), overlapped.push_back(j);
    std::sort(overlapped.begin(), overlapped.end());
    overlapped.erase(std::unique(overlapped.begin(), overlapped.end()), overlapped.end());
    std::shuffle(overlapped.begin(), overlapped.end(), random);
    for (size_t i : overlapped) {
      if (!goOn()) return false;
      const PlacedShape before = layout[i];
      sampledMove(layout, i, lanes, weights, random);
      ++moves;
      moved[i] = layout[i].shape != before.shape || layout[i].at != before.at;
    }
  }
  return false;
}

// Whether two placed shapes collide: their cores (see Shape::core)
// overlap, touching apart. An edge of one properly crosses an edge of the
// other, or a point of one (a pole's centre, a vertex, the middle of an
// edge) is strictly inside the other's core. The same both ways round.
// Can miss overlaps whose every crossing is at a vertex or along a shared
// line and that hold none of those points; apart() has the last word.
bool OverlapCompaction::colliding(const PlacedShape& a, const PlacedShape& b) const {
  return coresColliding(shapes_.at(a.part, a.shape), a.at, shapes_.at(b.part, b.shape), b.at);
}
// The weighted overlap of layout[i] as shape `k` at `at` with the others,
// given up (returning at least `enough`) once it reaches `enough`.
double OverlapCompaction::weightedOverlap(const std::vector<PlacedShape>& layout, size_t i, int k, IntPoint at,
                                          const std::vector<double>& weights, double enough) const {
  const size_t n = layout.size();
  const Shape& moving = shapes_.at(layout[i].part, k);
  double total = 0;
  for (size_t j = 0; j < n && total < enough; ++j) {
    if (j == i) continue;
    const Shape& other = shapes_.of(layout[j]);
    if (!coresColliding(moving, at, other, layout[j].at)) continue;
    total += weights[i * n + j] * proxy(moving, at, other, layout[j].at);
  }
  return total;
}

// The compaction's move by sampling, as sparrow does: places drawn at
// random near the part (within its own size) and anywhere on its bed or
// another, in random rotations; the few best (and apart) refined by
// coordinate descent, the best of them once more with finer steps. The
// weighted overlap proxy decides. Each place costs a few microseconds,
// no no-fit polygon: those of unique panels, built for each pair met,
// held the moves to about 50 a second among 200 of them (3000 now).
void OverlapCompaction::sampledMove(std::vector<PlacedShape>& layout, size_t i, const Lanes& lanes,
                                    const std::vector<double>& weights, std::mt19937& random) const {
  const int part = layout[i].part;
  const Shape& current = shapes_.at(part, layout[i].shape);
  const IntPoint centre = centreOf(layout[i]);
  const cInt halfX = (current.maxX - current.minX) / 2, halfY = (current.maxY - current.minY) / 2;
  // Where shape k's reference point may be on `lane`: its inner-fit rectangle.
  const auto fitOn = [&](int k, size_t lane) {
    const Shape& s = shapes_.at(part, k);
    return Box{lanes[lane].first - s.minX, -s.minY, lanes[lane].second - s.maxX, shapes_.height() - s.maxY};
  };
  const auto laneOf = [&](int k, IntPoint at) {
    return std::min(static_cast<size_t>(sheetOf(at.X + shapes_.at(part, k).maxX)), lanes.size() - 1);
  };
  const size_t here = laneOf(layout[i].shape, layout[i].at);
  std::vector<Sample> best;  // the kDescents best, apart by kDistinctShare of minSize, best first
  const cInt minSize = std::max<cInt>(1, std::min(current.maxX - current.minX, current.maxY - current.minY));
  const auto bound = [&] { return best.size() < kDescents ? kNoLimit : best.back().score; };
  const auto report = [&](const Sample& sample) {
    for (auto it = best.begin(); it != best.end(); ++it) {
      if (std::abs(it->at.X - sample.at.X) + std::abs(it->at.Y - sample.at.Y) < minSize * kDistinctShare &&
          it->shape == sample.shape) {
        if (sample.score < it->score) *it = sample;
        std::sort(best.begin(), best.end(), [](const Sample& a, const Sample& b) { return a.score < b.score; });
        return;
      }
    }
    if (best.size() == kDescents && sample.score >= best.back().score) return;
    if (best.size() == kDescents) best.pop_back();
    best.insert(std::upper_bound(best.begin(), best.end(), sample,
                                 [](const Sample& a, const Sample& b) { return a.score < b.score; }),
                sample);
  };
  const int rotations = static_cast<int>(shapes_.of(part).size());
  report({layout[i].shape, layout[i].at, weightedOverlap(layout, i, layout[i].shape, layout[i].at, weights, kNoLimit)});
  if (best.front().score == 0) return;
  for (int sample = 0; sample < kNearSamples + kFarSamples; ++sample) {
    const int k = static_cast<int>(random() % rotations);
    const bool near = sample < kNearSamples;
    Box box = fitOn(k, near ? here : random() % lanes.size());
    if (near) {
      const Shape& s = shapes_.at(part, k);
      const cInt atX = centre.X - (s.minX + s.maxX) / 2, atY = centre.Y - (s.minY + s.maxY) / 2;
      box = {std::max(box[0], atX - halfX), std::max(box[1], atY - halfY), std::min(box[2], atX + halfX),
             std::min(box[3], atY + halfY)};
    }
    if (box[2] < box[0] || box[3] < box[1]) continue;
    const IntPoint p{std::uniform_int_distribution<cInt>(box[0], box[2])(random),
                     std::uniform_int_distribution<cInt>(box[1], box[3])(random)};
    report({k, p, weightedOverlap(layout, i, k, p, weights, bound())});
  }
  // Coordinate descent (sparrow's): two places, one step either way along
  // a random axis; a place no worse is taken; a better one lengthens the
  // step by a tenth, else it halves and the axis changes (on a diagonal,
  // each of its two steps by the square root of that).
  const auto descend = [&](Sample from, double firstShare, double lastShare) {
    const Box fit = fitOn(from.shape, laneOf(from.shape, from.at));
    // Steps never longer than the room to move in (a run of successes would grow them without end).
    const double widest = std::max<double>(1, fit[2] - fit[0]), tallest = std::max<double>(1, fit[3] - fit[1]);
    double stepX = std::min(widest, minSize * firstShare), stepY = std::min(tallest, minSize * firstShare);
    const double last = std::max(1.0, minSize * lastShare);
    int axis = static_cast<int>(random() % 4);
    while ((stepX >= last || stepY >= last) && from.score > 0) {
      static constexpr int kAxes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
      const cInt dx = std::llround(kAxes[axis][0] * stepX), dy = std::llround(kAxes[axis][1] * stepY);
      bool better = false;
      if (dx != 0 || dy != 0) {  // a step rounded to nothing is a failed one
        Sample tried[2];
        for (int side = 0; side < 2; ++side) {
          const int sign = side ? -1 : 1;
          const IntPoint p{std::clamp(from.at.X + sign * dx, fit[0], fit[2]),
                           std::clamp(from.at.Y + sign * dy, fit[1], fit[3])};
          tried[side] = {from.shape, p, weightedOverlap(layout, i, from.shape, p, weights, from.score)};
        }
        const Sample& pick = tried[1].score < tried[0].score ? tried[1] : tried[0];
        better = pick.score < from.score;
        if (pick.score <= from.score) from = pick;
      }
      const double factor = better ? 1.1 : 0.5;
      if (axis != 1) stepX = std::min(widest, stepX * (axis == 0 ? factor : std::sqrt(factor)));
      if (axis != 0) stepY = std::min(tallest, stepY * (axis == 1 ? factor : std::sqrt(factor)));
      if (!better) axis = static_cast<int>(random() % 4);
    }
    return from;
  };
  for (const Sample& start : std::vector<Sample>(best)) report(descend(start, 0.25, 0.02));
  const Sample chosen = descend(best.front(), 0.01, 0.001);
  layout[i] = {part, chosen.shape, chosen.at};
}

// The exact check that ends a sampled separation: no two cores overlap
// (colliding() misses overlaps whose every crossing is at a vertex).
bool OverlapCompaction::apart(const std::vector<PlacedShape>& layout) const {
  for (size_t i = 0; i < layout.size(); ++i) {
    const Shape& a = shapes_.of(layout[i]);
    for (size_t j = i + 1; j < layout.size(); ++j) {
      const Shape& b = shapes_.of(layout[j]);
      if (!boxesApart(a, layout[i].at, b, layout[j].at) && coresOverlap(a, layout[i].at, b, layout[j].at)) return false;
    }
  }
  return true;
}

}  // namespace rotafab::jobs::nesting
