#include "jobs/EpsWriter.h"

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
    for (size_t i = 0; i < path.points.size(); ++i) {
      const Point2& p = path.points[i];
      // 0.001 pt is 0.000014 in: the sheet's 0.0001 in (kSheetDecimals) with room to spare.
      fmt::format_to(to, "{} {} {}", formatDecimal(p.x() * kPointsPerInch, 3), formatDecimal(p.y() * kPointsPerInch, 3),
                     i == 0 ? "m" : "l");
      buffer.push_back((i + 1) % kPointsPerLine == 0 ? '\n' : ' ');
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
