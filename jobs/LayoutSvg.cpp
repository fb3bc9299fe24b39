#include "jobs/LayoutSvg.h"

#include <fmt/format.h>

#include <algorithm>
#include <sstream>

namespace rotafab::jobs {

std::string layoutSvg(const std::vector<NestingPart>& parts, const NestingResult& result, const NestingOptions& options,
                      double margin) {
  const double width = options.strip ? std::max(result.stripLength, 1e-9) : options.width + 2 * margin;
  const double height = options.strip ? options.height : options.height + 2 * margin;
  const double gap = height * 0.05;
  const int sheets = std::max(1, result.sheets);
  const double total = sheets * height + (sheets - 1) * gap;
  std::ostringstream svg;
  svg << fmt::format(
      R"(<?xml version="1.0" encoding="UTF-8"?>)"
      "\n"
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="{:.4f}in" height="{:.4f}in" viewBox="0 0 {:.4f} {:.4f}">)"
      "\n",
      width, total, width, total);
  for (int s = 0; s < sheets; ++s) {
    const double top = s * (height + gap);
    svg << fmt::format(
        R"(<rect x="0" y="{:.4f}" width="{:.4f}" height="{:.4f}" fill="#f4f4f4" stroke="#000" stroke-width="{:.4f}"/>)"
        "\n",
        top, width, height, height * 0.002);
  }
  for (const auto& placement : result.placements) {
    const double top = (placement.sheet - 1) * (height + gap);
    std::string d;
    for (const auto& p : placedOutline(parts[placement.part], placement)) {
      d += fmt::format("{}{:.4f},{:.4f} ", d.empty() ? "M" : "L", p.x() + margin, top + height - (p.y() + margin));
    }
    svg << fmt::format(R"(<path d="{}Z" fill="#8ab4f8" stroke="#1a4f9c" stroke-width="{:.4f}"><title>{}</title></path>)"
                       "\n",
                       d, height * 0.001, parts[placement.part].name);
  }
  svg << "</svg>\n";
  return svg.str();
}

}  // namespace rotafab::jobs
