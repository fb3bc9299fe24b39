#include "jobs/SvgWriter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace rotafab::jobs {
namespace {

constexpr int kDecimals = kSheetDecimals;
constexpr double kHairlineInches = 0.001;
// The preview is for people's eyes: a thousandth of an inch is far finer
// than a screen or a print shows.
constexpr int kPreviewDecimals = 3;

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

namespace {

// The parts of an operation's paths in the order of their first path, each
// with its paths in drawing order.
std::vector<std::pair<std::string, std::vector<const DrawnPath*>>> partsOf(const SheetDrawing& sheet,
                                                                           Operation operation) {
  std::vector<std::pair<std::string, std::vector<const DrawnPath*>>> parts;
  for (const DrawnPath& path : sheet.paths) {
    if (path.operation != operation) continue;
    auto it = std::find_if(parts.begin(), parts.end(), [&](const auto& p) { return p.first == path.part; });
    if (it == parts.end()) it = parts.insert(parts.end(), {path.part, {}});
    it->second.push_back(&path);
  }
  return parts;
}

std::vector<Operation> operationsOf(const SheetDrawing& sheet) {
  std::vector<Operation> order;  // operations by their first path
  for (const DrawnPath& path : sheet.paths)
    if (std::find(order.begin(), order.end(), path.operation) == order.end()) order.push_back(path.operation);
  return order;
}

// A number of the path data: after a command letter or before a minus sign
// no space is needed (SVG's path grammar), elsewhere one.
void appendCoordinate(fmt::memory_buffer& buffer, int64_t units, int decimals, bool afterCommand) {
  if (!afterCommand && units >= 0) buffer.push_back(' ');
  appendUnits(buffer, units, decimals);
}

// The first point absolute (M), then relative moves (l) in whole units, so
// that they add up exactly to the rounded points; a circle as two half arcs
// from its rightmost point.
void appendPath(fmt::memory_buffer& buffer, double height, const DrawnPath& path, int decimals) {
  buffer.append(std::string_view("<path d=\"M"));
  if (path.circle) {
    // (At least one unit: a circle, however small, stays one when read back.)
    const int64_t r = std::max<int64_t>(1, unitsOf(path.circle->radius, decimals));
    const int64_t x = unitsOf(path.circle->centre.x(), decimals) + r;
    appendCoordinate(buffer, x, decimals, true);
    appendCoordinate(buffer, unitsOf(height - path.circle->centre.y(), decimals), decimals, false);
    for (const int64_t across : {-2 * r, 2 * r}) {
      buffer.push_back('a');
      appendCoordinate(buffer, r, decimals, true);
      appendCoordinate(buffer, r, decimals, false);
      buffer.append(std::string_view(" 0 1 0"));
      appendCoordinate(buffer, across, decimals, false);
      buffer.append(std::string_view(" 0"));
    }
    buffer.append(std::string_view("Z\"/>\n"));
    return;
  }
  int64_t x = 0, y = 0;
  for (size_t i = 0; i < path.points.size(); ++i) {
    const int64_t px = unitsOf(path.points[i].x(), decimals), py = unitsOf(height - path.points[i].y(), decimals);
    if (i == 1) buffer.push_back('l');
    appendCoordinate(buffer, px - x, decimals, i <= 1);
    appendCoordinate(buffer, py - y, decimals, false);
    x = px, y = py;
  }
  buffer.append(path.closed ? std::string_view("Z\"/>\n") : std::string_view("\"/>\n"));
}

}  // namespace

void writeSvg(const SheetDrawing& sheet, std::ostream& out) {
  checkDrawable(sheet);
  fmt::memory_buffer buffer;
  const auto to = std::back_inserter(buffer);

  const std::string width = formatDecimal(sheet.width, kDecimals), height = formatDecimal(sheet.height, kDecimals);
  fmt::format_to(to, "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n");
  fmt::format_to(to,
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" "
                 "xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" "
                 "xmlns:sodipodi=\"http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd\" version=\"1.1\" "
                 "width=\"{0}in\" height=\"{1}in\" viewBox=\"0 0 {0} {1}\">\n",
                 width, height);
  fmt::format_to(to, "<title>{}</title>\n",
                 xmlText(sheet.title.empty() ? fmt::format("sheet {}", sheet.index) : sheet.title));
  fmt::format_to(to, "<desc>rotafab sheet {} of {}; units: inches; bed {} x {} in, margin {} in</desc>\n", sheet.index,
                 sheet.sheetCount, width, height, formatDecimal(sheet.margin, kDecimals));

  for (Operation operation : operationsOf(sheet)) {
    const Rgb& rgb = sheet.colours.at(operation);
    const bool bed = operation == Operation::Outline;
    const std::string name(profiles::operationName(operation));
    fmt::format_to(to,
                   "<g id=\"{}\" fill=\"none\" stroke=\"#{:02x}{:02x}{:02x}\" stroke-width=\"{}\" "
                   "stroke-linecap=\"round\" stroke-linejoin=\"round\" inkscape:groupmode=\"layer\" "
                   "inkscape:label=\"{}\"{}>\n",
                   name, int{rgb.r}, int{rgb.g}, int{rgb.b}, formatDecimal(kHairlineInches, kDecimals),
                   bed ? "bed (not cut)" : name, bed ? " sodipodi:insensitive=\"true\"" : "");
    for (const auto& [part, paths] : partsOf(sheet, operation)) {
      if (!part.empty()) {
        fmt::format_to(to, "<g id=\"{}{}\">\n", xmlText(part), operation == Operation::Cut ? "" : "-" + name);
      }
      for (const DrawnPath* path : paths) appendPath(buffer, sheet.height, *path, kDecimals);
      if (!part.empty()) fmt::format_to(to, "</g>\n");
    }
    fmt::format_to(to, "</g>\n");
  }
  fmt::format_to(to, "</svg>\n");
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

void writeSvgPreview(const SheetDrawing& sheet, std::ostream& out, core::LengthUnit shownIn) {
  checkDrawable(sheet);
  fmt::memory_buffer buffer;
  const auto to = std::back_inserter(buffer);
  // Room above the bed for the title.
  constexpr double kTitle = 0.8;
  const std::string width = formatDecimal(sheet.width, kDecimals);
  fmt::format_to(to, "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n");
  fmt::format_to(to,
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{0}in\" height=\"{1}in\" "
                 "viewBox=\"0 {2} {0} {1}\">\n",
                 width, formatDecimal(sheet.height + kTitle, kDecimals), formatDecimal(-kTitle, kDecimals));
  const std::string title = sheet.title.empty() ? fmt::format("sheet {}", sheet.index) : sheet.title;
  fmt::format_to(to, "<title>{} (preview, not for cutting)</title>\n", xmlText(title));
  // The caption: which sheet, and the size of the stock it is cut from.
  fmt::format_to(
      to, "<text x=\"0\" y=\"-0.25\" font-family=\"sans-serif\" font-size=\"0.45\" fill=\"#222\">{}, {}</text>\n",
      xmlText(title), shownIn.size(sheet.width, sheet.height, 3));
  fmt::format_to(to,
                 "<rect class=\"material\" x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"#f3ead8\" "
                 "stroke=\"#999\" stroke-width=\"0.02\"/>\n",
                 width, formatDecimal(sheet.height, kDecimals));
  struct Look {
    Operation operation;
    const char* style;
  };
  // Etch and score under the cuts, as they are burnt.
  for (const Look& look :
       {Look{Operation::Etch, "stroke=\"#3b2a1a\" stroke-width=\"0.012\""},
        Look{Operation::Score, "stroke=\"#b03a2e\" stroke-width=\"0.015\" stroke-dasharray=\"0.1 0.06\""},
        Look{Operation::Cut, "stroke=\"#1f3a93\" stroke-width=\"0.02\""}}) {
    fmt::format_to(to, "<g class=\"{}\" fill=\"none\" {} stroke-linecap=\"round\" stroke-linejoin=\"round\">\n",
                   profiles::operationName(look.operation), look.style);
    for (const auto& [part, paths] : partsOf(sheet, look.operation)) {
      fmt::format_to(to, "<g class=\"{}\">\n", xmlText(part));
      for (const DrawnPath* path : paths) appendPath(buffer, sheet.height, *path, kPreviewDecimals);
      fmt::format_to(to, "</g>\n");
    }
    fmt::format_to(to, "</g>\n");
  }
  fmt::format_to(to, "</svg>\n");
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

}  // namespace rotafab::jobs
