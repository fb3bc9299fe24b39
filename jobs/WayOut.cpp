// A refused band structure's way out, tried (MakeSteps.h, withTriedWayOut()).

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/Cancellation.h"
#include "jobs/MakeSteps.h"
#include "jobs/SheetPlanner.h"

namespace rotafab::jobs::making {
namespace {

using geometry::Parameter;

// The search stops starting new tries after this long: a refusal that takes
// minutes to say what works is a hang to whoever waits.
constexpr double kWayOutSeconds = 45;
// A panel count below this is no longer the design.
constexpr int kFewestPanels = 12;

// One way out: make run with a panel count, a size, or both, changed.
struct Change {
  std::optional<int> panels;
  std::optional<double> size;  // inches, whole

  [[nodiscard]] std::string options(const MakeRequest& request) const {
    std::string said;
    if (panels) said += fmt::format("{} {}", request.names(Parameter::Panels), *panels);
    // (The size tried, rounded up: 36 in is 914.4 mm.)
    if (size) {
      said += fmt::format("{}{} {}", said.empty() ? "" : " ", request.names(Parameter::Size),
                          request.shownIn.value(*size, 2, 1));
    }
    return said;
  }
};

// The changes to try, nearest the design first: a size up to three times
// the one refused and down to an eighth of the panels, each step of either
// one step away; among as near, one who fixed the size (or the scale)
// takes fewer, larger panels first, one who did not a larger size, which
// keeps the design as drawn.
std::vector<Change> changesToTry(const MakeRequest& request, double side, int faces) {
  static constexpr std::array kPanelShares{1.0, 0.5, 0.25, 0.125};
  static constexpr std::array kSizeTimes{1.0, 1.25, 1.5, 2.0, 3.0};
  const bool sizeFixed = request.size || request.scale;
  const int asked = request.panels.value_or(faces);
  struct Step {
    size_t panels, size;
  };
  std::vector<Step> steps;
  for (size_t p = 0; p < kPanelShares.size(); ++p) {
    for (size_t s = 0; s < kSizeTimes.size(); ++s) {
      if (p + s > 0 && (p == 0 || std::lround(asked * kPanelShares[p]) >= kFewestPanels)) steps.push_back({p, s});
    }
  }
  std::stable_sort(steps.begin(), steps.end(), [&](const Step& a, const Step& b) {
    if (a.panels + a.size != b.panels + b.size) return a.panels + a.size < b.panels + b.size;
    return sizeFixed ? a.panels > b.panels : a.size > b.size;
  });
  std::vector<Change> changes;
  for (const Step& step : steps) {
    Change change;
    if (step.panels > 0 || request.panels) {
      change.panels = static_cast<int>(std::lround(asked * kPanelShares[step.panels]));
    }
    if (step.size > 0) {
      change.size = std::ceil(side * kSizeTimes[step.size]);
    } else {
      change.size = request.size;
    }
    changes.push_back(change);
  }
  return changes;
}

// What a try came to.
enum class Tried { Builds, OffTheBed, Refused };

// Builds `request` as make would, quietly; Builds if every band is
// fastened, every label etched, every panel fits the bed and the panels
// are within kPanelCountTolerance of a panel count asked.
Tried tryBuilding(const MakeRequest& request, const core::WorkContext& quiet, size_t& panels) {
  try {
    PlannedJob job;
    Sizing sizing;
    builtAsAsked(request, job, sizing, quiet);
    const double kerf = request.kerf.value_or(request.material.kerf);
    if (roomOnTheBed(structureParts(job.structure), request.machine, kerf) < 1) return Tried::OffTheBed;
    panels = job.structure.panels.size();
    // (A panel count far from the one it names is not that way out: mends took too many.)
    if (request.panels && !withinPanelCountTolerance(static_cast<double>(panels), *request.panels)) {
      return Tried::Refused;
    }
    return Tried::Builds;
  } catch (const core::Cancelled&) {
    throw;
  } catch (const std::exception&) {
    // (Refused too, for this or another reason: not a way out.)
    return Tried::Refused;
  }
}

}  // namespace

std::string withTriedWayOut(const MakeRequest& request, const StructureRefused& refused, double sideAsRefused,
                            int facesAsRefused, const core::WorkContext& context) {
  const std::string name = request.mesh.string();
  const double side = request.size.value_or(sideAsRefused);
  const std::vector<Change> changes = changesToTry(request, side, facesAsRefused);
  // Notes and progress of the tries go nowhere; the search's own progress is reported.
  const core::WorkContext quiet(context.executor(), context.cancellation());
  const auto began = std::chrono::steady_clock::now();
  int tries = 0;
  bool timedOut = false;
  std::optional<double> largestSize;
  std::optional<int> fewestPanels;
  // A panel count whose panels miss the bed at a size misses it at every larger one.
  std::map<int, double> offTheBedAt;
  size_t started = 0;
  for (const Change& change : changes) {
    context.check();
    const int panels = change.panels.value_or(0);
    if (change.size && offTheBedAt.count(panels) && *change.size >= offTheBedAt[panels]) continue;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    if (elapsed > kWayOutSeconds) {
      timedOut = true;
      break;
    }
    context.report({"geometry", "trying a way out: " + change.options(request), ++started, changes.size()});
    MakeRequest changed = request;
    changed.adviseWayOut = false;
    changed.panels = change.panels;
    if (change.size) {
      changed.size = change.size;
      changed.scale.reset();
    }
    size_t built = 0;
    const Tried result = tryBuilding(changed, quiet, built);
    if (result == Tried::Builds) {
      return fmt::format("{}: {}; {} builds it (tried: {} panels, every {} fastened and every number etched)", name,
                         refused.place, change.options(request), built, roomPlace(request.structure));
    }
    if (result == Tried::OffTheBed && change.size) offTheBedAt[panels] = *change.size;
    ++tries;
    if (change.size) largestSize = std::max(largestSize.value_or(0), *change.size);
    if (change.panels) fewestPanels = std::min(fewestPanels.value_or(panels), panels);
  }
  std::string said = fmt::format("{}: {}", name, refused.place);
  if (!refused.advice.empty()) said += "; " + refused.advice;
  if (tries == 0) return said;
  std::string ranges;
  if (largestSize) ranges = fmt::format("sizes up to {}", request.shownIn(*largestSize, 0));
  if (fewestPanels) ranges += fmt::format("{}down to {} panels", ranges.empty() ? "" : ", ", *fewestPanels);
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  return said + fmt::format("; nothing tried built it ({} tries in {:.0f} s{}: {})", tries, took,
                            timedOut ? ", the time allowed" : "", ranges);
}

}  // namespace rotafab::jobs::making
