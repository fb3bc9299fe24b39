#include "cli/ProgressLines.h"

#include <fmt/format.h>

namespace rotafab::cli {
namespace {

// How often a long first layout says how far it has got.
constexpr std::chrono::seconds kCountEvery{5};

const char* plural(size_t n) { return n == 1 ? "" : "s"; }

}  // namespace

void ProgressLines::operator()(const core::Progress& p) {
  std::string line;
  if (p.phase == "import" && p.step == "holes filled") {
    line = fmt::format("filled {} hole{} with one face each", p.done, plural(p.done));
  } else if (p.phase == "import" && p.step == "holes patched") {
    line = fmt::format("closed {} hole{} with triangles like the mesh's own", p.done, plural(p.done));
  } else if (p.phase == "geometry") {
    if (p.step == "band decomposition") line = fmt::format("band decomposition of {} faces", p.total);
    if (p.step == "panels split") {
      // done: bands cut off with a tab; total: those and the bands cut across their middle
      const size_t across = p.total > p.done ? p.total - p.done : 0;
      line =
          fmt::format("{} band{} cut off {} panel{} that would overlap {}, {}", p.total, plural(p.total),
                      p.total == 1 ? "a" : "the", plural(p.total), p.total == 1 ? "itself" : "themselves",
                      across == 0 ? std::string(p.total == 1 ? "fastened back by a tab" : "each fastened back by a tab")
                      : p.done == 0 ? std::string("cut across the middle, the other copy holding both halves")
                                    : fmt::format("{} with a tab, {} cut across the middle", p.done, across));
    }
    if (p.step == "larger, for the fasteners") {
      line = fmt::format("building again, larger, so that every fastener hole has room (try {})", p.done);
    }
    if (p.step == "smaller, for the bed") {
      line = fmt::format("building again, smaller, so that every part fits the bed (try {})", p.done);
    }
    if (p.step == "fastener holes") line = fmt::format("fastener holes on {} bands", p.total);
    if (p.step == "crossing holes") line = fmt::format("fastener holes at {} crossings", p.total);
    if (p.step == "weaving threads") line = "weaving threads (face tracing with twisted edges)";
    if (p.step == "ribbons") line = "ribbons, panels, unfolding";
    if (p.step == "labels") line = fmt::format("labels on {} panels", p.total);
  } else if (p.phase == "nesting") {
    std::string step;
    if (p.step.empty()) {
      // The start of the phase: its parts are the structure's panels.
      line = fmt::format("{} {} panels on {} beds", options_.rows ? "laying out in rows" : "nesting", p.total,
                         options_.bed);
    } else if (p.step == "first layout" && p.done == 0) {
      step = fmt::format("first layout of {} parts", p.total);
      nextCount_ = std::chrono::steady_clock::now() + kCountEvery;
    } else if (p.step == "first layout" && p.done < p.total) {
      const auto now = std::chrono::steady_clock::now();
      if (now > nextCount_) {
        step =
            fmt::format("first layout: {} of {} parts placed, {} sheet{}", p.done, p.total, p.sheets, plural(p.sheets));
        nextCount_ = now + kCountEvery;
      }
    } else if (p.step == "first layout") {
      const double left = p.budget - p.elapsed;
      step = fmt::format("{} sheet{}, last sheet {} long, in {:.1f} s; {}", p.sheets, plural(p.sheets),
                         options_.unit(p.length, 2), p.elapsed,
                         left >= 0.5 ? fmt::format("improving it for up to {:.0f} s more, while that helps", left)
                                     : std::string("no time left in --time to improve it"));
      nextCount_ = std::chrono::steady_clock::now() + kCountEvery;
    } else if (p.step == "improving" || p.step == "compacting" || p.step == "searching") {
      // Every better layout; that the search goes on, every few seconds.
      const auto now = std::chrono::steady_clock::now();
      if (p.step != "searching" || now > nextCount_) {
        const std::string layout = options_.strip ? fmt::format("strip {:.2f} long", p.length)
                                                  : fmt::format("{} sheet{}, last sheet {} long", p.sheets,
                                                                plural(p.sheets), options_.unit(p.length, 2));
        step = fmt::format("{}{} ({:.0f} of {:.0f} s)",
                           p.step == "searching"    ? "searching, best so far "
                           : p.step == "compacting" ? "compacting: "
                                                    : "",
                           layout, p.elapsed, p.budget);
        nextCount_ = now + kCountEvery;
      }
    }
    if (!step.empty()) line = options_.nestingPrefix + step;
  } else if (p.phase == "writing" && p.step.empty()) {
    line = fmt::format("writing {} sheet{} to {}", p.total, plural(p.total), options_.folder);
  }
  if (!line.empty()) fmt::print(stderr, "{}{}\n", options_.prefix, line);
}

}  // namespace rotafab::cli
