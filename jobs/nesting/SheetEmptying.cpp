#include "jobs/nesting/SheetEmptying.h"

#include <algorithm>
#include <chrono>
#include <numeric>

namespace rotafab::jobs::nesting {
namespace {

// Beds tried for each part, the roomiest first, and how long one bed may
// take to make room for it: a bed that cannot within that rarely can.
constexpr size_t kBedsTriedPerPart = 3;
constexpr std::chrono::milliseconds kMostPerInsertion{400};

}  // namespace

double SheetEmptying::partArea(const std::vector<PlacedShape>& bed) const {
  double area = 0;
  for (const PlacedShape& p : bed) area += shapes_.area(p.part);
  return area;
}

NestingResult SheetEmptying::empty(const std::vector<PlacedShape>& layout, int fewest, std::mt19937& random,
                                   const std::function<bool()>& goOn, int& moves,
                                   const std::function<void(int, double)>& fewer) const {
  // From the row of beds to each bed's own coordinates.
  std::vector<std::vector<PlacedShape>> beds;
  for (PlacedShape p : layout) {
    const size_t bed = static_cast<size_t>(std::max<cInt>(shapes_.rightOf(p) - 1, 0) / shapes_.pitch());
    if (beds.size() <= bed) beds.resize(bed + 1);
    p.at.X -= static_cast<cInt>(bed) * shapes_.pitch();
    beds[bed].push_back(p);
  }
  std::erase_if(beds, [](const auto& bed) { return bed.empty(); });
  // Beds that kept every part through a whole pass since the beds last changed.
  std::vector<char> stuck(beds.size(), 0);
  bool everyBedStuck = false;
  while (static_cast<int>(beds.size()) > fewest && goOn()) {
    size_t least = beds.size();
    for (size_t b = 0; b < beds.size(); ++b) {
      if (!stuck[b] && (least == beds.size() || partArea(beds[b]) < partArea(beds[least]))) least = b;
    }
    if (least == beds.size()) {
      everyBedStuck = true;
      break;
    }
    // Each part that finds room elsewhere leaves at once (the layout is
    // valid after every move), the largest first; one that does not stays
    // for the next pass.
    std::vector<PlacedShape> leaving = beds[least];
    std::stable_sort(leaving.begin(), leaving.end(), [&](const PlacedShape& a, const PlacedShape& b) {
      return shapes_.area(a.part) > shapes_.area(b.part);
    });
    bool moved = false;
    for (const PlacedShape& part : leaving) {
      if (!goOn()) break;
      std::vector<size_t> roomiest;
      for (size_t b = 0; b < beds.size(); ++b) {
        if (b != least) roomiest.push_back(b);
      }
      std::stable_sort(roomiest.begin(), roomiest.end(),
                       [&](size_t a, size_t b) { return partArea(beds[a]) < partArea(beds[b]); });
      for (size_t t = 0; t < std::min(kBedsTriedPerPart, roomiest.size()); ++t) {
        const auto until = std::chrono::steady_clock::now() + kMostPerInsertion;
        const auto bounded = [&] { return goOn() && std::chrono::steady_clock::now() < until; };
        if (compaction_.insert(beds[roomiest[t]], part, random, bounded, moves)) {
          std::erase_if(beds[least], [&](const PlacedShape& p) { return p.part == part.part; });
          moved = true;
          break;
        }
      }
    }
    if (beds[least].empty()) {
      beds.erase(beds.begin() + static_cast<long>(least));
      stuck.assign(beds.size(), 0);
      cInt lastLength = 0;
      for (const PlacedShape& p : beds.back()) lastLength = std::max(lastLength, shapes_.rightOf(p));
      fewer(static_cast<int>(beds.size()), static_cast<double>(lastLength) / kScale);
    } else if (!moved) {
      stuck[least] = 1;
    }
  }
  std::vector<std::pair<int, PlacedShape>> placed;
  for (size_t b = 0; b < beds.size(); ++b) {
    for (const PlacedShape& p : beds[b]) placed.emplace_back(static_cast<int>(b), p);
  }
  NestingResult result = shapes_.resultOf(placed, static_cast<int>(beds.size()));
  if (everyBedStuck) result.stopped = "no better layout";
  return result;
}

}  // namespace rotafab::jobs::nesting
