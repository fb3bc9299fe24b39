// The EPS a print-driver cutter receives: a valid DSC 3.0 EPSF whose page is
// the bed, which Ghostscript accepts, whose painted extent is the drawing's,
// and whose strokes carry each operation's exact profile colour where that
// operation's paths are (the driver picks the operation by colour).

#include "toolpath/EpsWriter.h"

#include <gtest/gtest.h>

#include "SheetFixture.h"

namespace rotafab::jobs::sheet_tests {
namespace {

constexpr double kPointsPerInch = 72;

std::string epsOf(const SheetDrawing& sheet) {
  std::ostringstream out;
  writeEps(sheet, out);
  return out.str();
}

std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(EpsWriter, DscHeaderDescribesTheBed) {
  const std::string eps = epsOf(sampleSheet());
  const auto lines = linesOf(eps);
  ASSERT_GT(lines.size(), 10u);
  EXPECT_EQ(lines[0], "%!PS-Adobe-3.0 EPSF-3.0");
  EXPECT_EQ(lines[1], "%%BoundingBox: 0 0 2304 1296");
  EXPECT_EQ(lines[2], "%%HiResBoundingBox: 0 0 2304 1296");
  EXPECT_NE(eps.find("\n%%Title: bunny (band) - sheet 2 of 3 <&> \"q\"\n"), std::string::npos);
  EXPECT_NE(eps.find("\n%%Creator: rotafab\n"), std::string::npos);
  EXPECT_NE(eps.find("\n%%Pages: 1\n"), std::string::npos);
  EXPECT_NE(eps.find("\n%%Page: 1 1\n"), std::string::npos);
  // The header comments end before any PostScript.
  const size_t end = eps.find("\n%%EndComments\n");
  ASSERT_NE(end, std::string::npos);
  for (const auto& line : linesOf(eps.substr(0, end))) EXPECT_EQ(line.rfind("%", 0), 0u) << line;
  EXPECT_EQ(lines.back(), "%%EOF");
  // DSC: lines of at most 255 bytes, 7-bit clean (%%DocumentData: Clean7Bit).
  for (const auto& line : lines) {
    EXPECT_LE(line.size(), 255u);
    for (char c : line) EXPECT_TRUE(c >= ' ' && c <= '~') << "byte " << int(c) << " in " << line;
  }
  // Hairlines: 0.001 in.
  EXPECT_NE(eps.find("\n0.072 setlinewidth"), std::string::npos);
  // No fonts: text arrives as strokes.
  EXPECT_EQ(eps.find("findfont"), std::string::npos);
  EXPECT_EQ(eps.find("show "), std::string::npos);
}

TEST(EpsWriter, BoundingBoxOfOtherBedsRoundsOutwards) {
  SheetDrawing sheet = sampleSheet();
  sheet.width = 24.3;  // 1749.6 pt
  sheet.height = 12;
  sheet.paths = {{Operation::Cut, {{1, 1}, {20, 11}}, false}};
  const std::string eps = epsOf(sheet);
  EXPECT_NE(eps.find("\n%%BoundingBox: 0 0 1750 864\n"), std::string::npos);
  EXPECT_NE(eps.find("\n%%HiResBoundingBox: 0 0 1749.6 864\n"), std::string::npos);
}

TEST(EpsWriter, TitleCannotBreakTheHeader) {
  SheetDrawing sheet = sampleSheet();
  sheet.title = "two\nlines \xc3\xa9 %%EOF";
  const auto lines = linesOf(epsOf(sheet));
  EXPECT_EQ(lines[3], "%%Title: two?lines ?? %%EOF");
  EXPECT_EQ(lines[4], "%%Creator: rotafab");
}

TEST(EpsWriter, GhostscriptPaintsExactlyTheDrawnExtent) {
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  const auto file = dir.write("sheet.eps", epsOf(sheet));
  const Box painted = ghostscriptBoundingBox(file);
  const Box drawn = extentOf(sheet);
  // Inside the bed...
  EXPECT_GE(painted.x0, 0);
  EXPECT_GE(painted.y0, 0);
  EXPECT_LE(painted.x1, sheet.width * kPointsPerInch);
  EXPECT_LE(painted.y1, sheet.height * kPointsPerInch);
  // ... and exactly the paths' extent (hairlines add 0.036 pt a side).
  EXPECT_NEAR(painted.x0, drawn.x0 * kPointsPerInch, 1.0);
  EXPECT_NEAR(painted.y0, drawn.y0 * kPointsPerInch, 1.0);
  EXPECT_NEAR(painted.x1, drawn.x1 * kPointsPerInch, 1.0);
  EXPECT_NEAR(painted.y1, drawn.y1 * kPointsPerInch, 1.0);

  // A drawing without an outline: the extent is the cut pentagon's corner
  // and the score line's end, not the outline any more.
  SheetDrawing inner = sheet;
  std::erase_if(inner.paths, [](const DrawnPath& p) { return p.operation == Operation::Outline; });
  const Box innerPainted = ghostscriptBoundingBox(dir.write("inner.eps", epsOf(inner)));
  const Box innerDrawn = extentOf(inner);
  EXPECT_NEAR(innerPainted.x0, innerDrawn.x0 * kPointsPerInch, 1.0);
  EXPECT_NEAR(innerPainted.y0, innerDrawn.y0 * kPointsPerInch, 1.0);
  EXPECT_NEAR(innerPainted.x1, innerDrawn.x1 * kPointsPerInch, 1.0);
  EXPECT_NEAR(innerPainted.y1, innerDrawn.y1 * kPointsPerInch, 1.0);
}

TEST(EpsWriter, RendersEachOperationInItsExactColourWhereItsPathsAre) {
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  const auto file = dir.write("sheet.eps", epsOf(sheet));

  // What a user does: render to PNG at 36 dpi; the page is the bed.
  const auto png = dir.path() / "sheet.png";
  CommandResult result =
      run("gs -q -dNOPAUSE -dBATCH -dSAFER -sDEVICE=png16m -r36 -dEPSCrop -sOutputFile=" + shellQuote(png) + " " +
          shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(pngSize(png), std::make_pair(1152, 648));

  // The same rendering as raw pixels, to look at them.
  const auto ppm = dir.path() / "sheet.ppm";
  result = run("gs -q -dNOPAUSE -dBATCH -dSAFER -sDEVICE=ppmraw -r36 -dEPSCrop -sOutputFile=" + shellQuote(ppm) + " " +
               shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err;
  const Image image = readPpm(ppm);
  ASSERT_EQ(image.width, 1152);
  ASSERT_EQ(image.height, 648);

  const double dpi = 36, pixel = 1 / dpi;
  for (Operation operation : profiles::kAllOperations) {
    SCOPED_TRACE(std::string(profiles::operationName(operation)));
    int count = 0;
    const Box pixels = pixelBox(image, sheet.colours.at(operation), dpi, sheet.height, &count);
    const Box drawn = extentOf(sheet, operation);
    ASSERT_GT(count, 20) << "no pixels of the profile colour";
    EXPECT_NEAR(pixels.x0, drawn.x0, 2 * pixel);
    EXPECT_NEAR(pixels.y0, drawn.y0, 2 * pixel);
    EXPECT_NEAR(pixels.x1, drawn.x1, 2 * pixel);
    EXPECT_NEAR(pixels.y1, drawn.y1, 2 * pixel);
  }
  // Nothing but the profile colours and the white page.
  std::map<Operation, Rgb> colours = sheet.colours;
  for (int row = 0; row < image.height; row += 1)
    for (int column = 0; column < image.width; ++column) {
      const Rgb p = image.at(column, row);
      bool known = p == Rgb{255, 255, 255};
      for (const auto& [operation, rgb] : colours) known = known || p == rgb;
      ASSERT_TRUE(known) << "pixel (" << column << ", " << row << ") is " << int(p.r) << " " << int(p.g) << " "
                         << int(p.b);
    }
}

TEST(EpsWriter, EveryEightBitColourSurvivesTheRoundTrip) {
  // r/255 is written with enough digits that any interpreter that rounds to
  // the nearest 8-bit value gets the profile's value back.
  TempDir dir;
  SheetDrawing sheet;
  sheet.width = 16;
  sheet.height = 16;
  for (int v = 0; v < 256; ++v) {
    const Rgb rgb{static_cast<uint8_t>(v), static_cast<uint8_t>(255 - v), static_cast<uint8_t>(v * 7 % 256)};
    const auto operation = profiles::kAllOperations[static_cast<size_t>(v % 4)];
    sheet.colours[operation] = rgb;
    SheetDrawing one = sheet;
    one.paths = {{operation, {{1 + v % 16 * 0.9, 1 + v / 16 * 0.9}, {1.5 + v % 16 * 0.9, 1.5 + v / 16 * 0.9}}, false}};
    std::ostringstream eps;
    writeEps(one, eps);
    const std::string text = eps.str();
    const size_t at = text.find(" c\n");
    ASSERT_NE(at, std::string::npos);
    const size_t start = text.rfind('\n', at) + 1;
    std::istringstream values(text.substr(start, at - start));
    double r, g, b;
    values >> r >> g >> b;
    EXPECT_EQ(std::lround(r * 255), rgb.r);
    EXPECT_EQ(std::lround(g * 255), rgb.g);
    EXPECT_EQ(std::lround(b * 255), rgb.b);
    EXPECT_LT(std::abs(r * 255 - rgb.r), 1e-3);
  }
}

TEST(EpsWriter, CoordinatesHaveAThousandthOfAPoint) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths = {{Operation::Cut, {{1.0000001, 2.00001}, {3.123456, 4.5}}, false}};
  const std::string eps = epsOf(sheet);
  // The first point, then the move to the next in whole thousandths, which
  // add up to its rounded position (224.889 324).
  EXPECT_NE(eps.find("\n72 144.001 m 152.889 179.999 r s\n"), std::string::npos) << eps;
}

TEST(EpsWriter, CirclesAreArcs) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths = {circlePath(Operation::Cut, {{1, 2}, 0.0625})};
  const std::string eps = epsOf(sheet);
  EXPECT_NE(eps.find("\n72 144 4.5 o\n"), std::string::npos) << eps;
  TempDir dir;
  const Box painted = ghostscriptBoundingBox(dir.write("circle.eps", eps));
  // Ghostscript's box of the painted ink, to the point: the circle's, 9 pt across.
  EXPECT_NEAR(painted.x0, 67.5, 1.0);
  EXPECT_NEAR(painted.x1, 76.5, 1.0);
  EXPECT_NEAR(painted.y0, 139.5, 1.0);
  EXPECT_NEAR(painted.y1, 148.5, 1.0);
}

}  // namespace
}  // namespace rotafab::jobs::sheet_tests
