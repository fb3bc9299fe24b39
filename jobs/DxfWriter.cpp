#include "jobs/DxfWriter.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <iterator>
#include <stdexcept>

namespace rotafab::jobs {
namespace {

constexpr int kDecimals = kSheetDecimals;

class GroupWriter {
 public:
  explicit GroupWriter(fmt::memory_buffer& buffer) : out_(buffer) {}
  // Group codes right-aligned in 3 columns, as AutoCAD writes them.
  void operator()(int code, std::string_view value) {
    groupCode(code);
    out_.append(value.data(), value.data() + value.size());
    out_.push_back('\n');
  }
  void operator()(int code, int value) {
    groupCode(code);
    appendInteger(value);
    out_.push_back('\n');
  }
  void point(int code, double x, double y, double z = 0) {
    const double values[3] = {x, y, z};
    for (int i = 0; i < 3; ++i) {
      groupCode(code + 10 * i);
      appendDecimal(out_, values[i], kDecimals);
      out_.push_back('\n');
    }
  }

 private:
  void groupCode(int code) {
    if (code >= 0 && code < 10) out_.append(std::string_view("  "));
    if (code >= 10 && code < 100) out_.push_back(' ');
    appendInteger(code);
    out_.push_back('\n');
  }
  void appendInteger(int value) {
    char digits[16];
    const auto [end, error] = std::to_chars(digits, digits + sizeof digits, value);
    out_.append(digits, end);
  }

  fmt::memory_buffer& out_;
};

}  // namespace

std::string dxfLayerName(Operation operation) {
  std::string name(profiles::operationName(operation));
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

Rgb aciColour(int index) {
  static constexpr std::array<Rgb, 10> kStandard{{{0, 0, 0},
                                                  {255, 0, 0},
                                                  {255, 255, 0},
                                                  {0, 255, 0},
                                                  {0, 255, 255},
                                                  {0, 0, 255},
                                                  {255, 0, 255},
                                                  {0, 0, 0},  // 7: foreground, black on paper
                                                  {128, 128, 128},
                                                  {192, 192, 192}}};
  if (index < 1 || index > 255) throw std::invalid_argument(fmt::format("ACI colour {} is not in 1..255", index));
  if (index <= 9) return kStandard[static_cast<size_t>(index)];
  if (index >= 250) {
    static constexpr std::array<uint8_t, 6> kGrays{51, 91, 132, 173, 214, 255};
    const uint8_t v = kGrays[static_cast<size_t>(index - 250)];
    return {v, v, v};
  }
  // 10-249: hue (index / 10 - 1) * 15 degrees; index % 10 picks the shade
  // (value 255, 165, 127, 76, 38) and, when odd, half saturation.
  static constexpr std::array<double, 5> kValues{255, 165, 127, 76, 38};
  const int hue = (index / 10 - 1) * 15, shade = index % 10;
  const double high = kValues[static_cast<size_t>(shade / 2)];
  const double low = shade % 2 ? high / 2 : 0;
  const double f = (hue % 60) / 60.0, rising = low + (high - low) * f, falling = high - (high - low) * f;
  std::array<double, 3> c{};
  switch (hue / 60) {
    case 0:
      c = {high, rising, low};
      break;
    case 1:
      c = {falling, high, low};
      break;
    case 2:
      c = {low, high, rising};
      break;
    case 3:
      c = {low, falling, high};
      break;
    case 4:
      c = {rising, low, high};
      break;
    default:
      c = {high, low, falling};
      break;
  }
  auto byte = [](double v) { return static_cast<uint8_t>(std::lround(v)); };
  return {byte(c[0]), byte(c[1]), byte(c[2])};
}

int nearestAci(Rgb rgb) {
  auto distance = [&rgb](Rgb other) {
    const int dr = rgb.r - other.r, dg = rgb.g - other.g, db = rgb.b - other.b;
    return dr * dr + dg * dg + db * db;
  };
  int best = 7;
  int bestDistance = std::min(distance({0, 0, 0}), distance({255, 255, 255}));
  for (int index = 1; index <= 255; ++index) {
    if (index == 7) continue;
    const int d = distance(aciColour(index));
    if (d < bestDistance || (d == bestDistance && index < best)) {
      best = index;
      bestDistance = d;
    }
  }
  return best;
}

void writeDxf(const SheetDrawing& sheet, std::ostream& out) {
  checkDrawable(sheet);
  fmt::memory_buffer buffer;
  GroupWriter group(buffer);

  group(999, printableAscii(
                 fmt::format("rotafab sheet {} of {}: {}; units: inches", sheet.index, sheet.sheetCount, sheet.title)));
  group(0, "SECTION");
  group(2, "HEADER");
  group(9, "$ACADVER");
  group(1, "AC1009");
  group(9, "$INSBASE");
  group.point(10, 0, 0);
  group(9, "$EXTMIN");
  group.point(10, 0, 0);
  group(9, "$EXTMAX");
  group.point(10, sheet.width, sheet.height);
  group(9, "$LIMMIN");
  group(10, formatDecimal(0, kDecimals));
  group(20, formatDecimal(0, kDecimals));
  group(9, "$LIMMAX");
  group(10, formatDecimal(sheet.width, kDecimals));
  group(20, formatDecimal(sheet.height, kDecimals));
  group(9, "$LUNITS");
  group(70, 2);  // decimal
  group(9, "$MEASUREMENT");
  group(70, 0);  // imperial
  group(0, "ENDSEC");

  group(0, "SECTION");
  group(2, "TABLES");
  group(0, "TABLE");
  group(2, "LTYPE");
  group(70, 1);
  group(0, "LTYPE");
  group(2, "CONTINUOUS");
  group(70, 0);
  group(3, "Solid line");
  group(72, 65);
  group(73, 0);
  group(40, formatDecimal(0, kDecimals));
  group(0, "ENDTAB");
  group(0, "TABLE");
  group(2, "LAYER");
  group(70, static_cast<int>(sheet.colours.size()));
  for (Operation operation : profiles::kAllOperations) {
    const auto colour = sheet.colours.find(operation);
    if (colour == sheet.colours.end()) continue;
    group(0, "LAYER");
    group(2, dxfLayerName(operation));
    group(70, 0);
    group(62, nearestAci(colour->second));
    group(6, "CONTINUOUS");
  }
  group(0, "ENDTAB");
  group(0, "ENDSEC");

  group(0, "SECTION");
  group(2, "ENTITIES");
  for (const DrawnPath& path : sheet.paths) {
    const std::string layer = dxfLayerName(path.operation);
    if (path.circle) {
      group(0, "CIRCLE");
      group(8, layer);
      group.point(10, path.circle->centre.x(), path.circle->centre.y());
      group(40, formatDecimal(path.circle->radius, kDecimals));
      continue;
    }
    if (!path.closed && path.points.size() == 2) {
      group(0, "LINE");
      group(8, layer);
      group.point(10, path.points[0].x(), path.points[0].y());
      group.point(11, path.points[1].x(), path.points[1].y());
      continue;
    }
    group(0, "POLYLINE");
    group(8, layer);
    group(66, 1);  // vertices follow
    group.point(10, 0, 0);
    group(70, path.closed ? 1 : 0);
    for (const Point2& p : path.points) {
      group(0, "VERTEX");
      group(8, layer);
      group.point(10, p.x(), p.y());
    }
    group(0, "SEQEND");
    group(8, layer);
  }
  group(0, "ENDSEC");
  group(0, "EOF");
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

}  // namespace rotafab::jobs
