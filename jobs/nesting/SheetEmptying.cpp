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
  std::vector<char> triedInVain(beds.size(), 0);
  while (static_cast<int>(beds.size()) > fewest && goOn()) {
    // The least-filled bed not yet tried in vain since the beds last changed.
    size_t least = beds.size();
    for (size_t b = 0; b < beds.size(); ++b) {
      if (!triedInVain[b] && (least == beds.size() || partArea(beds[b]) < partArea(beds[least]))) least = b;
    }
    if (least == beds.size()) break;
    std::vector<PlacedShape> leaving = beds[least];
    std::stable_sort(leaving.begin(), leaving.end(), [&](const PlacedShape& a, const PlacedShape& b) {
      return shapes_.area(a.part) > shapes_.area(b.part);
    });
    std::vector<std::vector<PlacedShape>> others = beds;
    others.erase(others.begin() + static_cast<long>(least));
    bool emptied = true;
    for (const PlacedShape& part : leaving) {
      std::vector<size_t> roomiest(others.size());
      std::iota(roomiest.begin(), roomiest.end(), 0);
      std::stable_sort(roomiest.begin(), roomiest.end(),
                       [&](size_t a, size_t b) { return partArea(others[a]) < partArea(others[b]); });
      bool placed = false;
      for (size_t t = 0; t < std::min(kBedsTriedPerPart, roomiest.size()) && !placed; ++t) {
        const auto until = std::chrono::steady_clock::now() + kMostPerInsertion;
        const auto bounded = [&] { return goOn() && std::chrono::steady_clock::now() < until; };
        placed = compaction_.insert(others[roomiest[t]], part, random, bounded, moves);
      }
      if (!placed) {
        emptied = false;
        break;
      }
    }
    if (emptied) {
      beds = std::move(others);
      triedInVain.assign(beds.size(), 0);
      cInt lastLength = 0;
      for (const PlacedShape& p : beds.back()) lastLength = std::max(lastLength, shapes_.rightOf(p));
      fewer(static_cast<int>(beds.size()), static_cast<double>(lastLength) / kScale);
    } else {
      triedInVain[least] = 1;
    }
  }
  std::vector<std::pair<int, PlacedShape>> placed;
  for (size_t b = 0; b < beds.size(); ++b) {
    for (const PlacedShape& p : beds[b]) placed.emplace_back(static_cast<int>(b), p);
  }
  return shapes_.resultOf(placed, static_cast<int>(beds.size()));
}

}  // namespace rotafab::jobs::nesting
