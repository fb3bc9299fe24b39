#pragma once
// A sheet with every operation on it, shared by the writer suites, and the
// small helpers they share: running the real tools (Ghostscript, rsvg-convert,
// ezdxf) on what the writers produce, reading their answers, and comparing
// paths read back with the paths drawn.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/HersheyFont.h"
#include "support/TestSupport.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs::sheet_tests {

using rotafab::test::CommandResult;
using rotafab::test::readFile;
using rotafab::test::run;
using rotafab::test::TempDir;

struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  void add(const Point2& p) {
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  [[nodiscard]] bool empty() const { return x0 > x1; }
};

// Profile colours chosen so that a writer that rounds r/255 the wrong way, or
// swaps channels, shows: no two share a channel value.
inline std::map<Operation, Rgb> sampleColours() {
  return {{Operation::Cut, {0, 0, 255}},
          {Operation::Score, {201, 17, 34}},
          {Operation::Etch, {255, 204, 0}},
          {Operation::Outline, {0, 153, 51}}};
}

// Paths of each operation kept apart, so that each colour's pixels can be
// told from the others'; the outline is asymmetric in y, so that a flip shows.
inline SheetDrawing sampleSheet() {
  SheetDrawing sheet;
  sheet.index = 2;
  sheet.sheetCount = 3;
  sheet.title = "bunny (band) - sheet 2 of 3 <&> \"q\"";
  sheet.colours = sampleColours();
  // An irregular pentagon panel.
  DrawnPath pentagon{Operation::Cut, {}, true};
  for (int k = 0; k < 5; ++k) {
    const double angle = 2 * std::numbers::pi * k / 5 + 0.1;
    pentagon.points.emplace_back(5.123456789 + (2 - 0.1 * k) * std::cos(angle), 5.0 + (2 - 0.1 * k) * std::sin(angle));
  }
  sheet.paths.push_back(circlePath(Operation::Cut, {{5.2345678, 5.0}, 0.0625}));  // a fastener hole in it
  sheet.paths.push_back(pentagon);
  sheet.paths.push_back(
      {Operation::Cut, {{10.1234567, 2.5}, {13.6543219, 2.5}, {13.6543219, 6.25}, {10.1234567, 6.25}}, true});
  sheet.paths.push_back({Operation::Score, {{16.2, 3.3}, {20.7, 8.1}, {22.05, 3.9}}, false});
  sheet.paths.push_back({Operation::Score, {{16.0, 12.0}, {24.5, 14.75}}, false});
  for (auto& stroke : geometry::HersheyFont::simplex().strokes("12", Point2(3.0, 12.0), 0.5, 0.0))
    sheet.paths.push_back({Operation::Etch, stroke, false});
  sheet.paths.push_back({Operation::Outline, {{0.5, 0.75}, {27.3, 0.75}, {27.3, 16.9}, {0.5, 16.9}}, true});
  return sheet;
}

inline Box extentOf(const SheetDrawing& sheet, std::optional<Operation> only = std::nullopt) {
  Box box;
  for (const auto& path : sheet.paths)
    if (!only || path.operation == *only)
      for (const auto& p : path.points) box.add(p);
  return box;
}

// Paths read back from a file: compared with the drawing operation by
// operation (files may group them), in order within each operation.
struct ReadPath {
  Operation operation = Operation::Cut;
  std::vector<Point2> points;
  bool closed = false;
  std::optional<Circle> circle = {};  // a circle, written as one: no points read
};

// The files give coordinates to kSheetDecimals (0.0001 in): each read back
// within half a unit on each axis of the drawing.
constexpr double kWrittenTolerance = 0.00005 * 1.41421356237 + 1e-9;

inline void expectSamePaths(const SheetDrawing& sheet, const std::vector<ReadPath>& read,
                            double tolerance = kWrittenTolerance) {
  for (Operation operation : profiles::kAllOperations) {
    SCOPED_TRACE(std::string(profiles::operationName(operation)));
    std::vector<const DrawnPath*> drawn;
    std::vector<const ReadPath*> back;
    for (const auto& p : sheet.paths)
      if (p.operation == operation) drawn.push_back(&p);
    for (const auto& p : read)
      if (p.operation == operation) back.push_back(&p);
    ASSERT_EQ(back.size(), drawn.size());
    for (size_t i = 0; i < drawn.size(); ++i) {
      EXPECT_EQ(back[i]->closed, drawn[i]->closed) << "path " << i;
      ASSERT_EQ(back[i]->circle.has_value(), drawn[i]->circle.has_value()) << "path " << i;
      if (drawn[i]->circle) {
        EXPECT_LE((back[i]->circle->centre - drawn[i]->circle->centre).norm(), tolerance) << "path " << i;
        EXPECT_LE(std::abs(back[i]->circle->radius - drawn[i]->circle->radius), tolerance) << "path " << i;
        continue;
      }
      ASSERT_EQ(back[i]->points.size(), drawn[i]->points.size()) << "path " << i;
      for (size_t k = 0; k < drawn[i]->points.size(); ++k)
        EXPECT_LE((back[i]->points[k] - drawn[i]->points[k]).norm(), tolerance)
            << "path " << i << " point " << k << ": read " << back[i]->points[k].transpose() << ", drawn "
            << drawn[i]->points[k].transpose();
    }
  }
}

// Ghostscript's bbox device on a PostScript file: the box of what it paints,
// in points. Fails the test when gs does not accept the file.
inline Box ghostscriptBoundingBox(const std::filesystem::path& file) {
  const CommandResult result = run("gs -q -dNOPAUSE -dBATCH -dSAFER -sDEVICE=bbox '" + file.string() + "'");
  EXPECT_EQ(result.status, 0) << result.err;
  std::smatch match;
  const std::regex hires(R"(%%HiResBoundingBox: ([-0-9.e]+) ([-0-9.e]+) ([-0-9.e]+) ([-0-9.e]+))");
  Box box;
  if (!std::regex_search(result.err, match, hires)) {
    ADD_FAILURE() << "no %%HiResBoundingBox from gs: " << result.err;
    return box;
  }
  box.x0 = std::stod(match[1]);
  box.y0 = std::stod(match[2]);
  box.x1 = std::stod(match[3]);
  box.y1 = std::stod(match[4]);
  return box;
}

// A binary PPM (P6) image.
struct Image {
  int width = 0, height = 0;
  std::string pixels;  // RGB, rows from the top
  [[nodiscard]] Rgb at(int column, int row) const {
    const size_t i = 3 * (static_cast<size_t>(row) * width + column);
    return {static_cast<uint8_t>(pixels[i]), static_cast<uint8_t>(pixels[i + 1]), static_cast<uint8_t>(pixels[i + 2])};
  }
};

inline Image readPpm(const std::filesystem::path& file) {
  const std::string bytes = readFile(file);
  Image image;
  size_t at = 0;
  std::array<int, 3> numbers{};  // width, height, maximum
  auto skipSpaceAndComments = [&] {
    while (at < bytes.size() && (std::isspace(static_cast<unsigned char>(bytes[at])) || bytes[at] == '#')) {
      if (bytes[at] == '#')
        while (at < bytes.size() && bytes[at] != '\n') ++at;
      else
        ++at;
    }
  };
  if (bytes.compare(0, 2, "P6") != 0) {
    ADD_FAILURE() << file << " is not a binary PPM";
    return image;
  }
  at = 2;
  for (int& n : numbers) {
    skipSpaceAndComments();
    size_t used = 0;
    n = std::stoi(bytes.substr(at, 10), &used);
    at += used;
  }
  ++at;  // the single whitespace before the raster
  image.width = numbers[0];
  image.height = numbers[1];
  EXPECT_EQ(numbers[2], 255);
  image.pixels = bytes.substr(at);
  EXPECT_EQ(image.pixels.size(), 3u * image.width * image.height);
  return image;
}

// Width and height from a PNG's IHDR chunk.
inline std::pair<int, int> pngSize(const std::filesystem::path& file) {
  const std::string bytes = readFile(file);
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || bytes.compare(12, 4, "IHDR") != 0) {
    ADD_FAILURE() << file << " is not a PNG";
    return {0, 0};
  }
  auto big = [&](size_t at) {
    int value = 0;
    for (size_t i = 0; i < 4; ++i) value = value << 8 | static_cast<unsigned char>(bytes[at + i]);
    return value;
  };
  return {big(16), big(20)};
}

// The box, in sheet inches, of the pixels that have exactly `colour`; the
// image covers the bed at `dpi`, top row first.
inline Box pixelBox(const Image& image, Rgb colour, double dpi, double bedHeight, int* count = nullptr) {
  Box box;
  int n = 0;
  for (int row = 0; row < image.height; ++row)
    for (int column = 0; column < image.width; ++column)
      if (image.at(column, row) == colour) {
        ++n;
        box.add(Point2((column + 0.5) / dpi, bedHeight - (row + 0.5) / dpi));
      }
  if (count) *count = n;
  return box;
}

inline std::string shellQuote(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

}  // namespace rotafab::jobs::sheet_tests
