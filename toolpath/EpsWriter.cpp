#include "toolpath/EpsWriter.h"

#include <fmt/format.h>

#include <cmath>
#include <iterator>
#include <optional>
#include <stdexcept>

namespace rotafab::jobs {
namespace {

constexpr double kPointsPerInch = 72.0;
constexpr double kHairlineInches = 0.001;
constexpr int kPointsPerLine = 8;  // keeps lines well under DSC's 255 bytes
constexpr int kDecimals = 3;       // of a point

}  // namespace

void writeEps(const SheetDrawing& sheet, std::ostream& out) {
  checkDrawable(sheet);
  const double widthPt = sheet.width * kPointsPerInch, heightPt = sheet.height * kPointsPerInch;
  fmt::memory_buffer buffer;
  const auto to = std::back_inserter(buffer);
  auto line = [&buffer](std::string_view text) {
    buffer.append(text);
    buffer.push_back('\n');
  };

  line("%!PS-Adobe-3.0 EPSF-3.0");
  // Integer box: the smallest that contains the bed (DSC rounds outwards).
  fmt::format_to(to, "%%BoundingBox: 0 0 {} {}\n", static_cast<long long>(std::ceil(widthPt - 1e-9)),
                 static_cast<long long>(std::ceil(heightPt - 1e-9)));
  fmt::format_to(to, "%%HiResBoundingBox: 0 0 {} {}\n", formatDecimal(widthPt, 4), formatDecimal(heightPt, 4));
  fmt::format_to(to, "%%Title: {}\n",
                 printableAscii(sheet.title.empty() ? fmt::format("sheet {}", sheet.index) : sheet.title));
  line("%%Creator: rotafab");
  line("%%Pages: 1");
  line("%%LanguageLevel: 1");
  line("%%DocumentData: Clean7Bit");
  line("%%EndComments");
  line("%%BeginProlog");
  line("% Coordinates in points (1/72 in) from the bed's bottom-left corner, y up.");
  line("% The stroke colour names the operation (the machine profile's colour table).");
  line("/rotafab 8 dict def");
  line("rotafab begin");
  line("/m { moveto } bind def");
  line("/l { lineto } bind def");
  line("/s { stroke } bind def");
  line("/cs { closepath stroke } bind def");
  line("/r { rlineto } bind def");
  line("/o { 0 360 arc closepath stroke } bind def");
  line("/c { setrgbcolor } bind def");
  line("end");
  line("%%EndProlog");
  line("%%Page: 1 1");
  line("rotafab begin");
  line("gsave");
  fmt::format_to(to, "{} setlinewidth 1 setlinejoin 1 setlinecap\n",
                 formatDecimal(kHairlineInches * kPointsPerInch, 4));

  std::optional<Operation> current;
  for (const DrawnPath& path : sheet.paths) {
    if (path.operation != current) {
      const Rgb& rgb = sheet.colours.at(path.operation);
      fmt::format_to(to, "% {}\n{} {} {} c\n", profiles::operationName(path.operation), formatDecimal(rgb.r / 255.0, 6),
                     formatDecimal(rgb.g / 255.0, 6), formatDecimal(rgb.b / 255.0, 6));
      current = path.operation;
    }
    // 0.001 pt is 0.000014 in: the sheet's 0.0001 in (kSheetDecimals) with room to spare.
    const auto units = [](double inches) { return unitsOf(inches * kPointsPerInch, kDecimals); };
    const auto number = [&buffer](int64_t value) {
      appendUnits(buffer, value, kDecimals);
      buffer.push_back(' ');
    };
    if (path.circle) {
      number(units(path.circle->centre.x()));
      number(units(path.circle->centre.y()));
      number(units(path.circle->radius));
      line("o");
      continue;
    }
    // The first point, then moves in whole units, which add up exactly to
    // the rounded points.
    int64_t x = 0, y = 0;
    for (size_t i = 0; i < path.points.size(); ++i) {
      const int64_t px = units(path.points[i].x()), py = units(path.points[i].y());
      number(px - x);
      number(py - y);
      buffer.push_back(i == 0 ? 'm' : 'r');
      buffer.push_back((i + 1) % kPointsPerLine == 0 ? '\n' : ' ');
      x = px, y = py;
    }
    line(path.closed ? "cs" : "s");
  }

  line("grestore");
  line("end");
  line("showpage");
  line("%%Trailer");
  line("%%EOF");
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

}  // namespace rotafab::jobs
