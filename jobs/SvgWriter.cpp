#include "jobs/SvgWriter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace rotafab::jobs {
namespace {

constexpr int kDecimals = 9;
constexpr double kHairlineInches = 0.001;

}  // namespace

std::string xmlText(std::string_view text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      switch (c) {
        case '&':
          out += "&amp;";
          break;
        case '<':
          out += "&lt;";
          break;
        case '>':
          out += "&gt;";
          break;
        case '"':
          out += "&quot;";
          break;
        default:
          out += (c < 0x20 && c != '\t') ? '?' : static_cast<char>(c);
      }
      ++i;
      continue;
    }
    // A UTF-8 sequence: its length from the lead byte, then continuation bytes.
    const size_t length = (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3 : (c & 0xF8) == 0xF0 ? 4 : 0;
    bool valid = length > 0 && c != 0xC0 && c != 0xC1 && c < 0xF5 && i + length <= text.size();
    for (size_t k = 1; valid && k < length; ++k) valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (valid) {
      out.append(text.substr(i, length));
      i += length;
    } else {
      out += '?';
      ++i;
    }
  }
  return out;
}

void writeSvg(const SheetDrawing& sheet, std::ostream& out) {
  checkDrawable(sheet);
  fmt::memory_buffer buffer;
  const auto to = std::back_inserter(buffer);

  const std::string width = formatDecimal(sheet.width, kDecimals), height = formatDecimal(sheet.height, kDecimals);
  fmt::format_to(to, "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n");
  fmt::format_to(to,
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{0}in\" height=\"{1}in\" "
                 "viewBox=\"0 0 {0} {1}\">\n",
                 width, height);
  fmt::format_to(to, "<title>{}</title>\n",
                 xmlText(sheet.title.empty() ? fmt::format("sheet {}", sheet.index) : sheet.title));
  fmt::format_to(to, "<desc>rotafab sheet {} of {}; units: inches; bed {} x {} in, margin {} in</desc>\n", sheet.index,
                 sheet.sheetCount, width, height, formatDecimal(sheet.margin, kDecimals));

  std::vector<Operation> order;  // operations by their first path
  for (const DrawnPath& path : sheet.paths)
    if (std::find(order.begin(), order.end(), path.operation) == order.end()) order.push_back(path.operation);

  for (Operation operation : order) {
    const Rgb& rgb = sheet.colours.at(operation);
    fmt::format_to(to,
                   "<g id=\"{}\" fill=\"none\" stroke=\"#{:02x}{:02x}{:02x}\" stroke-width=\"{}\" "
                   "stroke-linecap=\"round\" stroke-linejoin=\"round\">\n",
                   profiles::operationName(operation), int{rgb.r}, int{rgb.g}, int{rgb.b},
                   formatDecimal(kHairlineInches, kDecimals));
    for (const DrawnPath& path : sheet.paths) {
      if (path.operation != operation) continue;
      fmt::format_to(to, "<path d=\"");
      for (size_t i = 0; i < path.points.size(); ++i)
        fmt::format_to(to, "{}{} {}", i == 0 ? "M" : " L", formatDecimal(path.points[i].x(), kDecimals),
                       formatDecimal(sheet.height - path.points[i].y(), kDecimals));
      fmt::format_to(to, "{}\"/>\n", path.closed ? " Z" : "");
    }
    fmt::format_to(to, "</g>\n");
  }
  fmt::format_to(to, "</svg>\n");
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

}  // namespace rotafab::jobs
