// The SVG that LightBurn and Inkscape import: the bed in inches, one group per
// operation in the profile's colour, and exactly the drawn geometry (read back
// here by a small reader, and rendered by librsvg, whose output Ghostscript
// measures in points as it does the EPS).

#include "jobs/SvgWriter.h"

#include "toolpath/SheetReader.h"

#include <gtest/gtest.h>

#include "SheetFixture.h"

namespace rotafab::jobs::sheet_tests {
namespace {

std::string svgOf(const SheetDrawing& sheet) {
  std::ostringstream out;
  writeSvg(sheet, out);
  return out.str();
}

std::map<std::string, std::string> attributesOf(const std::string& tag) {
  std::map<std::string, std::string> attributes;
  const std::regex attribute(R"re(([A-Za-z_:][-A-Za-z0-9_:.]*)="([^"]*)")re");
  for (auto it = std::sregex_iterator(tag.begin(), tag.end(), attribute); it != std::sregex_iterator(); ++it)
    attributes[(*it)[1]] = (*it)[2];
  return attributes;
}

// What the test reads back: the document's size and every path, with the
// attributes of its group.
struct SvgContent {
  std::map<std::string, std::string> root;
  std::map<Operation, std::map<std::string, std::string>> groups;
  std::vector<ReadPath> paths;  // in sheet coordinates (y flipped back)
};

// A reader for the subset of SVG the writer uses: <g> elements directly in
// <svg>, each holding <path d> elements of M, then absolute L or relative l
// pairs, and Z; or circles of two arcs.
SvgContent readSvg(const std::string& svg) {
  SvgContent content;
  std::smatch match;
  if (!std::regex_search(svg, match, std::regex(R"(<svg\b[^>]*>)"))) {
    ADD_FAILURE() << "no <svg> element";
    return content;
  }
  content.root = attributesOf(match[0]);
  double viewHeight = 0;
  {
    std::istringstream box(content.root["viewBox"]);
    double x, y, w;
    box >> x >> y >> w >> viewHeight;
  }
  const std::regex group(R"(<g\b([^>]*)>([\s\S]*?)</g>)");
  const std::regex path(R"(<path\b([^>]*)/>)");
  for (auto g = std::sregex_iterator(svg.begin(), svg.end(), group); g != std::sregex_iterator(); ++g) {
    const auto attributes = attributesOf((*g)[1]);
    const auto operation = profiles::operationNamed(attributes.count("id") ? attributes.at("id") : "");
    if (!operation) {
      ADD_FAILURE() << "group without an operation id: " << (*g)[1];
      continue;
    }
    EXPECT_FALSE(content.groups.contains(*operation)) << "two groups for one operation";
    content.groups[*operation] = attributes;
    const std::string body = (*g)[2];
    for (auto p = std::sregex_iterator(body.begin(), body.end(), path); p != std::sregex_iterator(); ++p) {
      const auto d = attributesOf((*p)[1])["d"];
      ReadPath read;
      read.operation = *operation;
      // Command letters may touch their numbers ("M1 2l3-4"), as SVG allows,
      // and a command's letter may be left out before its next numbers.
      const std::regex token(R"([MLlaZ]|[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?|\S)");
      std::vector<std::string> tokens;
      for (auto t = std::sregex_iterator(d.begin(), d.end(), token); t != std::sregex_iterator(); ++t)
        tokens.push_back((*t)[0]);
      const auto isNumber = [](const std::string& t) { return std::isdigit(static_cast<unsigned char>(t.back())); };
      char command = 0;
      double x = 0, y = 0;
      for (size_t t = 0; t < tokens.size(); ++t) {
        if (!isNumber(tokens[t])) {
          command = tokens[t][0];
          if (command == 'M') {
            EXPECT_TRUE(read.points.empty()) << "a second M in one path: " << d;
          }
          if (command == 'Z') read.closed = true;
          if (command == 'a') {
            // A circle: two half arcs from its rightmost point, back to it.
            std::vector<double> numbers;
            for (size_t k = t; k < tokens.size() && numbers.size() < 14; ++k)
              if (isNumber(tokens[k])) numbers.push_back(std::stod(tokens[k]));
            if (numbers.size() != 14u) {
              ADD_FAILURE() << "a circle of " << numbers.size() << " numbers: " << d;
              break;
            }
            const double r = numbers[0];
            EXPECT_EQ(std::vector<double>(numbers.begin(), numbers.begin() + 7),
                      (std::vector<double>{r, r, 0, 1, 0, -2 * r, 0}))
                << d;
            EXPECT_EQ(std::vector<double>(numbers.begin() + 7, numbers.end()),
                      (std::vector<double>{r, r, 0, 1, 0, 2 * r, 0}))
                << d;
            EXPECT_EQ(tokens.back(), "Z") << d;
            read.circle = Circle{{x - r, viewHeight - y}, r};
            read.points.clear();
            read.closed = true;
            break;
          }
          continue;
        }
        if (!(command == 'M' || command == 'L' || command == 'l') || read.closed || t + 1 >= tokens.size() ||
            !isNumber(tokens[t + 1])) {
          ADD_FAILURE() << "unexpected \"" << tokens[t] << "\" in " << d;
          break;
        }
        const double a = std::stod(tokens[t]), b = std::stod(tokens[t + 1]);
        if (command == 'l') {
          x += a, y += b;
        } else {
          x = a, y = b;
        }
        read.points.emplace_back(x, viewHeight - y);
        ++t;
      }
      content.paths.push_back(read);
    }
  }
  return content;
}

std::string hex(Rgb rgb) {
  char text[8];
  std::snprintf(text, sizeof text, "#%02x%02x%02x", rgb.r, rgb.g, rgb.b);
  return text;
}

TEST(SvgWriter, DocumentIsTheBedInInches) {
  const SvgContent svg = readSvg(svgOf(sampleSheet()));
  EXPECT_EQ(svg.root.at("width"), "32in");
  EXPECT_EQ(svg.root.at("height"), "18in");
  EXPECT_EQ(svg.root.at("viewBox"), "0 0 32 18");
  EXPECT_EQ(svg.root.at("xmlns"), "http://www.w3.org/2000/svg");
  EXPECT_EQ(svg.root.at("version"), "1.1");
}

TEST(SvgWriter, PathsReadBackAsDrawn) {
  const SheetDrawing sheet = sampleSheet();
  const SvgContent svg = readSvg(svgOf(sheet));
  expectSamePaths(sheet, svg.paths);
  ASSERT_EQ(svg.groups.size(), 4u);
  for (const auto& [operation, attributes] : svg.groups) {
    SCOPED_TRACE(std::string(profiles::operationName(operation)));
    EXPECT_EQ(attributes.at("stroke"), hex(sheet.colours.at(operation)));
    EXPECT_EQ(attributes.at("fill"), "none");
    EXPECT_EQ(attributes.at("stroke-width"), "0.001");
  }
}

TEST(SvgWriter, GroupsOnlyTheOperationsDrawnInTheirFirstOrder) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths = {{Operation::Etch, {{1, 1}, {2, 2}}, false},
                 {Operation::Cut, {{3, 3}, {4, 3}, {4, 4}}, true},
                 {Operation::Etch, {{5, 5}, {6, 6}}, false}};
  const std::string text = svgOf(sheet);
  EXPECT_LT(text.find("<g id=\"etch\""), text.find("<g id=\"cut\""));
  EXPECT_EQ(text.find("<g id=\"score\""), std::string::npos);
  EXPECT_EQ(text.find("<g id=\"outline\""), std::string::npos);
  expectSamePaths(sheet, readSvg(text).paths);
}

TEST(SvgWriter, TitleIsEscaped) {
  SheetDrawing sheet = sampleSheet();
  sheet.title = "a<b & \"c\"\x01 \xc3\xa9 \xff";
  const std::string text = svgOf(sheet);
  EXPECT_NE(text.find("<title>a&lt;b &amp; &quot;c&quot;? \xc3\xa9 ?</title>"), std::string::npos) << text;
}

TEST(SvgWriter, XmllintAcceptsIt) {
  TempDir dir;
  SheetDrawing sheet = sampleSheet();
  sheet.title = "a<b & \"c\"\x01 \xc3\xa9 \xff";
  const auto file = dir.write("sheet.svg", svgOf(sheet));
  const CommandResult result = run("xmllint --noout " + shellQuote(file));
  EXPECT_EQ(result.status, 0) << result.err << " (xmllint is in Debian's libxml2-utils)";
}

TEST(SvgWriter, LibrsvgDrawsTheSameSheetAsTheEps) {
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  const auto file = dir.write("sheet.svg", svgOf(sheet));

  // A PNG at 36 dpi is the bed at 36 dpi: the size in inches is understood.
  const auto png = dir.path() / "sheet.png";
  CommandResult result = run("rsvg-convert -f png -d 36 -p 36 -o " + shellQuote(png) + " " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err << " (rsvg-convert is in Debian's librsvg2-bin)";
  EXPECT_EQ(pngSize(png), std::make_pair(1152, 648));

  // As PostScript, librsvg's drawing can be measured and rasterized without
  // anti-aliasing by Ghostscript, exactly as the EPS is.
  const auto ps = dir.path() / "sheet.ps";
  result = run("rsvg-convert -f ps -o " + shellQuote(ps) + " " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err;
  const Box painted = ghostscriptBoundingBox(ps);
  const Box drawn = extentOf(sheet);
  EXPECT_NEAR(painted.x0, drawn.x0 * 72, 1.0);
  EXPECT_NEAR(painted.y0, drawn.y0 * 72, 1.0);
  EXPECT_NEAR(painted.x1, drawn.x1 * 72, 1.0);
  EXPECT_NEAR(painted.y1, drawn.y1 * 72, 1.0);

  const auto ppm = dir.path() / "sheet.ppm";
  result = run("gs -q -dNOPAUSE -dBATCH -dSAFER -sDEVICE=ppmraw -r36 -sOutputFile=" + shellQuote(ppm) + " " +
               shellQuote(ps));
  ASSERT_EQ(result.status, 0) << result.err;
  const Image image = readPpm(ppm);
  ASSERT_EQ(image.width, 1152);
  ASSERT_EQ(image.height, 648);
  for (Operation operation : profiles::kAllOperations) {
    SCOPED_TRACE(std::string(profiles::operationName(operation)));
    int count = 0;
    const Box pixels = pixelBox(image, sheet.colours.at(operation), 36, sheet.height, &count);
    const Box mine = extentOf(sheet, operation);
    ASSERT_GT(count, 20) << "no pixels of the profile colour";
    EXPECT_NEAR(pixels.x0, mine.x0, 2 / 36.0);
    EXPECT_NEAR(pixels.y0, mine.y0, 2 / 36.0);
    EXPECT_NEAR(pixels.x1, mine.x1, 2 / 36.0);
    EXPECT_NEAR(pixels.y1, mine.y1, 2 / 36.0);
  }
}

TEST(SvgWriter, InkscapeReadsTheSameSheet) {
  // Inkscape is what our users open sheets with (and LightBurn, which is not
  // free software and cannot run here). Its command line reports the
  // bounding box of every element it parsed, in its own pixels.
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  const auto file = dir.write("sheet.svg", svgOf(sheet));
  const std::string environment = "HOME=" + shellQuote(dir.path()) + " ";
  CommandResult result = run(environment + "inkscape --query-all " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err << " (inkscape is in Debian's inkscape)";
  std::map<std::string, std::array<double, 4>> boxes;  // id -> x, y, width, height
  std::istringstream lines(result.out);
  for (std::string line; std::getline(lines, line);) {
    std::array<double, 4> box{};
    char id[128];
    if (std::sscanf(line.c_str(), "%127[^,],%lf,%lf,%lf,%lf", id, &box[0], &box[1], &box[2], &box[3]) == 5) {
      boxes[id] = box;
    }
  }
  ASSERT_FALSE(boxes.empty()) << result.out;
  for (Operation operation : profiles::kAllOperations) {
    const std::string id(profiles::operationName(operation));
    SCOPED_TRACE(id);
    ASSERT_TRUE(boxes.contains(id)) << result.out;
    // Inkscape's pixels are 1/96 in, y down from the top of the bed; its
    // boxes include the hairline's width.
    const Box mine = extentOf(sheet, operation);
    const auto& [x, y, width, height] = boxes.at(id);
    EXPECT_NEAR(x / 96, mine.x0, 0.002);
    EXPECT_NEAR((x + width) / 96, mine.x1, 0.002);
    EXPECT_NEAR(sheet.height - (y + height) / 96, mine.y0, 0.002);
    EXPECT_NEAR(sheet.height - y / 96, mine.y1, 0.002);
  }
  // And it exports the bed at its size: 32 x 18 in at 36 dpi.
  const auto png = dir.path() / "inkscape.png";
  result = run(environment + "inkscape --export-type=png --export-dpi=36 --export-area-page --export-filename=" +
               shellQuote(png) + " " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(pngSize(png), std::make_pair(1152, 648));
}

// Each part's paths are one group, so that a panel can be picked whole in
// Inkscape; the bed's outline is a locked layer of its own; and `run` reads
// the sheet back with every path.
TEST(SvgWriter, EachPartIsAGroupAndTheBedALayerOfItsOwn) {
  TempDir dir;
  SheetDrawing sheet = sampleSheet();
  for (DrawnPath& path : sheet.paths) {
    if (path.operation == Operation::Outline) continue;
    path.part = path.operation == Operation::Cut && path.points.size() == 5 ? "panel-17" : "panel-4";
  }
  const std::string svg = svgOf(sheet);
  EXPECT_NE(svg.find("<g id=\"panel-17\">"), std::string::npos);
  EXPECT_NE(svg.find("<g id=\"panel-4-score\">"), std::string::npos);
  EXPECT_NE(svg.find("<g id=\"panel-4-etch\">"), std::string::npos);
  std::smatch bed;
  ASSERT_TRUE(std::regex_search(svg, bed, std::regex(R"(<g id="outline"[^>]*>)")));
  const auto attributes = attributesOf(bed[0]);
  EXPECT_EQ(attributes.at("inkscape:groupmode"), "layer");
  EXPECT_EQ(attributes.at("inkscape:label"), "bed (not cut)");
  EXPECT_EQ(attributes.at("sodipodi:insensitive"), "true");
  const auto file = dir.write("sheet.svg", svg);
  EXPECT_EQ(run("xmllint --noout " + shellQuote(file)).status, 0);

  // Inkscape finds the panel's group, with the box of its cut.
  const CommandResult result = run("HOME=" + shellQuote(dir.path()) + " inkscape --query-all " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err;
  std::smatch box;
  ASSERT_TRUE(std::regex_search(result.out, box, std::regex(R"(panel-17,([-0-9.]+),([-0-9.]+),([-0-9.]+),([-0-9.]+))")))
      << result.out;
  Box pentagon{1e9, 1e9, -1e9, -1e9};
  const auto pentagonPath = std::find_if(sheet.paths.begin(), sheet.paths.end(), [](const DrawnPath& p) {
    return p.operation == Operation::Cut && p.points.size() == 5;
  });
  ASSERT_NE(pentagonPath, sheet.paths.end());
  for (const Point2& p : pentagonPath->points) {
    pentagon.x0 = std::min(pentagon.x0, p.x()), pentagon.x1 = std::max(pentagon.x1, p.x());
  }
  EXPECT_NEAR(std::stod(box[1]) / 96, pentagon.x0, 0.002);
  EXPECT_NEAR((std::stod(box[1]) + std::stod(box[3])) / 96, pentagon.x1, 0.002);

  // Read back for `run`: the same paths, each of its operation (the file keeps them part by part).
  const SheetDrawing read = readSheetSvg(file);
  ASSERT_EQ(read.paths.size(), sheet.paths.size());
  for (const DrawnPath& written : sheet.paths) {
    const bool found = std::any_of(read.paths.begin(), read.paths.end(), [&](const DrawnPath& p) {
      if (p.operation != written.operation || p.points.size() != written.points.size()) return false;
      for (size_t k = 0; k < p.points.size(); ++k)
        if ((p.points[k] - written.points[k]).norm() > kWrittenTolerance) return false;
      return true;
    });
    EXPECT_TRUE(found);
  }
}

// The preview is for people: wide strokes in dark colours on the material's
// colour, which librsvg draws at the bed's size (plus the title).
TEST(SvgWriter, ThePreviewShowsTheSheetToPeople) {
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  std::ostringstream out;
  writeSvgPreview(sheet, out);
  const auto file = dir.write("sheet.preview.svg", out.str());
  EXPECT_EQ(run("xmllint --noout " + shellQuote(file)).status, 0);
  EXPECT_EQ(out.str().find(" id=\""), std::string::npos) << "classes only: many previews share one HTML page";
  const auto png = dir.path() / "preview.png";
  const CommandResult result = run("rsvg-convert -f png -d 36 -p 36 -o " + shellQuote(png) + " " + shellQuote(file));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(pngSize(png).first, 1152);
  const auto ps = dir.path() / "preview.ps", ppm = dir.path() / "preview.ppm";
  ASSERT_EQ(run("rsvg-convert -f ps -o " + shellQuote(ps) + " " + shellQuote(file)).status, 0);
  ASSERT_EQ(
      run("gs -q -dNOPAUSE -dBATCH -dSAFER -sDEVICE=ppmraw -r36 -sOutputFile=" + shellQuote(ppm) + " " + shellQuote(ps))
          .status,
      0);
  const Image image = readPpm(ppm);
  int count = 0;
  pixelBox(image, Rgb{0x1f, 0x3a, 0x93}, 36, sheet.height + 0.8, &count);
  EXPECT_GT(count, 100) << "the cuts drawn wide enough to see at 36 dpi";
}

// `rotafab run` and the daemon cut from the SVG: its circles come back as
// circles (and the polygon a toolpath follows), its moves as the points.
TEST(SheetReader, CirclesAndMovesReadBack) {
  TempDir dir;
  const SheetDrawing sheet = sampleSheet();
  const SheetDrawing read = readSheetSvg(dir.write("sheet.svg", svgOf(sheet)));
  ASSERT_EQ(read.paths.size(), sheet.paths.size());
  std::vector<ReadPath> paths;
  for (const DrawnPath& path : read.paths) paths.push_back({path.operation, path.points, path.closed, path.circle});
  expectSamePaths(sheet, paths);
  const auto circle = std::find_if(read.paths.begin(), read.paths.end(), [](const DrawnPath& p) { return p.circle; });
  ASSERT_NE(circle, read.paths.end());
  EXPECT_EQ(circle->points.size(), static_cast<size_t>(kCircleSides));
  for (const Point2& p : circle->points) EXPECT_GE((p - circle->circle->centre).norm(), circle->circle->radius - 1e-12);
}

// Sheets written before the moves (absolute L) are still in queues.
TEST(SheetReader, ReadsAbsoluteLines) {
  TempDir dir;
  const std::string head =
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"32in\" height=\"18in\" viewBox=\"0 0 32 18\">\n"
      "<desc>rotafab sheet 1 of 1; units: inches; bed 32 x 18 in, margin 0.25 in</desc>\n"
      "<g id=\"cut\" fill=\"none\" stroke=\"#0000ff\">\n";
  const SheetDrawing read = readSheetSvg(dir.write("old.svg", head + "<path d=\"M1 2 L3 4 L5 2 Z\"/>\n</g>\n</svg>\n"));
  ASSERT_EQ(read.paths.size(), 1u);
  EXPECT_TRUE(read.paths[0].closed);
  EXPECT_EQ(read.paths[0].points, (std::vector<Point2>{{1, 16}, {3, 14}, {5, 16}}));
  // Arcs that are not a circle's two halves are not rotafab's: an ellipse,
  // or one half circle drawn twice.
  for (const auto& [name, d] : {std::pair{"arc.svg", "M1 2a1 2 0 1 0-2 0a1 2 0 1 0 2 0Z"},
                                std::pair{"half.svg", "M1 2a1 1 0 1 0-2 0a1 1 0 1 1 2 0Z"}}) {
    try {
      readSheetSvg(dir.write(name, head + "<path d=\"" + d + "\"/>\n</g>\n</svg>\n"));
      ADD_FAILURE() << d << " read as a circle";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(std::string(name) + ":4: path data: arcs that are not a circle"),
                std::string::npos)
          << error.what();
    }
  }
}

}  // namespace
}  // namespace rotafab::jobs::sheet_tests
