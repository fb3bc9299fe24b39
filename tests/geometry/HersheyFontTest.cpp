// Etched labels: Hershey's Simplex Roman from hershey-fonts-data, mapped from
// ASCII, scaled to the capital height, set along any direction; and the mark
// that tells 6 from 9 on a panel seen upside down.

#include "geometry/HersheyFont.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

using test::TempDir;

// The box of some points.
struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  void add(const Point2& p) {
    x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
  }
};

const HersheyFont& font() { return HersheyFont::simplex(); }

Box boxOf(const std::vector<Polyline>& strokes) {
  Box box;
  for (const auto& stroke : strokes)
    for (const auto& p : stroke) box.add(p);
  return box;
}

double lengthOf(const std::vector<Polyline>& strokes) {
  double length = 0;
  for (const auto& stroke : strokes)
    for (size_t i = 1; i < stroke.size(); ++i) length += (stroke[i] - stroke[i - 1]).norm();
  return length;
}

TEST(HersheyFont, SimplexHasTheAsciiGlyphs) {
  EXPECT_EQ(font().glyphCount(), 96);  // ' ' to '~', and the record in DEL's place
  for (int c = ' '; c <= '~'; ++c) {
    const std::string text(1, static_cast<char>(c));
    EXPECT_NO_THROW(font().strokes(text, Point2(0, 0), 1.0)) << text;
    EXPECT_GT(font().advance(text, 1.0), 0) << text;
  }
}

TEST(HersheyFont, KnownGlyphsInFontUnits) {
  // At height 21 one font unit is one inch. 'A' (Hershey 501): bounds -9..9,
  // three strokes (two sides, the bar), apex (0, -12) and feet at +-8 on the
  // baseline, so from x = 1 to 17 and y = 0 to 21 once set at the origin.
  const auto a = font().strokes("A", Point2(0, 0), 21);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0], (Polyline{{9, 21}, {1, 0}}));
  EXPECT_EQ(a[1], (Polyline{{9, 21}, {17, 0}}));
  EXPECT_EQ(a[2], (Polyline{{4, 7}, {14, 7}}));
  EXPECT_DOUBLE_EQ(font().advance("A", 21), 18);
  // '1' (Hershey 701): one stroke of 4 points, the flag then the stem.
  const auto one = font().strokes("1", Point2(0, 0), 21);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].size(), 4u);
  EXPECT_EQ(one[0].back(), Point2(11, 0));
  EXPECT_DOUBLE_EQ(font().advance("1", 21), 20);
  // Space draws nothing but advances.
  EXPECT_TRUE(font().strokes(" ", Point2(0, 0), 21).empty());
  EXPECT_DOUBLE_EQ(font().advance(" ", 21), 16);
  // The period sits on the baseline (it does not in futural.jhf).
  EXPECT_NEAR(boxOf(font().strokes(".", Point2(0, 0), 21)).y0, 0, 1e-12);
}

TEST(HersheyFont, CapitalsAndDigitsAreHeightTallOnTheBaseline) {
  for (const char* text : {"H", "E", "0", "1", "4", "7", "8", "10"}) {
    SCOPED_TRACE(text);
    const Box box = boxOf(font().strokes(text, Point2(2, 3), 0.25));
    EXPECT_NEAR(box.y0, 3, 1e-12);
    EXPECT_NEAR(box.y1, 3.25, 1e-12);
    EXPECT_GE(box.x0, 2);
    EXPECT_LE(box.x1, 2 + font().advance(text, 0.25));
  }
}

TEST(HersheyFont, SizeScalesWithHeight) {
  const std::string text = "Panel 12";
  const double small = font().advance(text, 0.2), large = font().advance(text, 0.5);
  EXPECT_GT(small, 0);
  EXPECT_NEAR(large / small, 2.5, 1e-12);
  // The advance of a text is the sum of its characters'.
  EXPECT_NEAR(font().advance("12", 0.3), font().advance("1", 0.3) + font().advance("2", 0.3), 1e-12);
  const Box a = boxOf(font().strokes(text, Point2(0, 0), 0.2)), b = boxOf(font().strokes(text, Point2(0, 0), 0.5));
  EXPECT_NEAR((b.x1 - b.x0) / (a.x1 - a.x0), 2.5, 1e-9);
  EXPECT_NEAR((b.y1 - b.y0) / (a.y1 - a.y0), 2.5, 1e-9);
  EXPECT_NEAR(lengthOf(font().strokes(text, Point2(0, 0), 0.5)) / lengthOf(font().strokes(text, Point2(0, 0), 0.2)),
              2.5, 1e-9);
  // The second character starts where the first one's advance ends.
  const auto two = font().strokes("2", Point2(font().advance("1", 0.3), 0), 0.3);
  const auto both = font().strokes("12", Point2(0, 0), 0.3);
  ASSERT_EQ(both.size(), 2u);
  ASSERT_EQ(two.size(), 1u);
  for (size_t k = 0; k < two[0].size(); ++k) EXPECT_NEAR((both[1][k] - two[0][k]).norm(), 0, 1e-12);
}

TEST(HersheyFont, RotationTurnsTheTextRigidlyAboutTheOrigin) {
  const Point2 origin(4, 7);
  const auto flat = font().strokes("86", origin, 0.4, 0);
  for (double angle : {std::numbers::pi / 2, 1.0, -2.5, std::numbers::pi}) {
    SCOPED_TRACE(angle);
    const auto turned = font().strokes("86", origin, 0.4, angle);
    ASSERT_EQ(turned.size(), flat.size());
    EXPECT_NEAR(lengthOf(turned), lengthOf(flat), 1e-12);
    const Eigen::Rotation2Dd rotation(angle);
    for (size_t s = 0; s < flat.size(); ++s) {
      ASSERT_EQ(turned[s].size(), flat[s].size());
      for (size_t k = 0; k < flat[s].size(); ++k)
        EXPECT_NEAR((turned[s][k] - (origin + rotation * (flat[s][k] - origin))).norm(), 0, 1e-12);
    }
  }
  // Reading upwards (90 degrees): the text grows along +y, its capitals
  // stand towards -x.
  const Box up = boxOf(font().strokes("HH", origin, 0.4, std::numbers::pi / 2));
  EXPECT_NEAR(up.x0, origin.x() - 0.4, 1e-12);
  EXPECT_NEAR(up.x1, origin.x(), 1e-12);
  EXPECT_GT(up.y1 - up.y0, 0.4);
}

TEST(HersheyFont, UnknownCharactersAreRefusedByName) {
  for (const std::string& text : {std::string("12\xc3\xa9"), std::string("a\tb"), std::string("7\x7f"),
                                  std::string("line\nbreak"), std::string("nul\0x", 5)}) {
    SCOPED_TRACE(text);
    EXPECT_THROW(font().strokes(text, Point2(0, 0), 1), std::invalid_argument);
    EXPECT_THROW(font().advance(text, 1), std::invalid_argument);
  }
  try {
    font().strokes("12\xc3\xa9", Point2(0, 0), 1);
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("\\xc3 (code 195) at position 3"), std::string::npos) << error.what();
  }
  EXPECT_THROW(font().strokes("1", Point2(0, 0), 0), std::invalid_argument);
  EXPECT_THROW(font().strokes("1", Point2(0, 0), -1), std::invalid_argument);
  EXPECT_THROW(font().advance("1", std::nan("")), std::invalid_argument);
  EXPECT_TRUE(font().strokes("", Point2(0, 0), 1).empty());
  EXPECT_EQ(font().advance("", 1), 0);
}

TEST(HersheyFont, LoadReadsWrappedRecordsAndRefusesBrokenFiles) {
  TempDir dir;
  // The '1' of rowmans.jhf, once on one line and once wrapped after column 12.
  const auto one = dir.write("one.jhf", "  701  5H\\NJPISFS[\n  701  5H\\NJ\nPISFS[\n");
  const HersheyFont font = HersheyFont::load(one);
  EXPECT_EQ(font.glyphCount(), 2);  // ' ' and '!'
  EXPECT_EQ(font.strokes(" ", Point2(0, 0), 21), font.strokes("!", Point2(0, 0), 21));
  EXPECT_EQ(font.strokes(" ", Point2(0, 0), 21), HersheyFont::simplex().strokes("1", Point2(0, 0), 21));
  EXPECT_THROW(font.strokes("\"", Point2(0, 0), 1), std::invalid_argument);  // beyond the file's glyphs

  auto refusal = [&](const std::string& bytes) {
    try {
      HersheyFont::load(dir.write("bad.jhf", bytes));
    } catch (const std::runtime_error& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  const std::string bad = (dir.path() / "bad.jhf").string();
  EXPECT_EQ(refusal("  699  1JZ\n  701 x5H\\NJPISFS[\n"), bad + ":2: the count \" x5\" is not a number");
  EXPECT_EQ(refusal("  701  6H\\NJPISFS[\n"),
            bad + ":1: the glyph announces 6 coordinate pairs but the file ends after 5");
  EXPECT_EQ(refusal("  701  4H\\NJPISFS[\n"), bad + ":1: text after the 4 coordinate pairs the glyph announces");
  EXPECT_EQ(refusal(""), bad + ": no glyphs in the Hershey font");
  EXPECT_THROW(HersheyFont::load(dir.path() / "missing.jhf"), std::runtime_error);
}

TEST(HersheyFont, LabelsThatReadAsAnotherNumberUpsideDownAreMarked) {
  // Marked: upside down they read as another number.
  for (const char* label : {"6", "9", "16", "61", "10", "66", "99", "196", "6008"}) {
    EXPECT_TRUE(readsDifferentlyUpsideDown(label)) << label;
    EXPECT_EQ(labelText(label), std::string(label) + ".");
  }
  // Not marked: the same number either way up, or no number upside down.
  for (const char* label : {"", "0", "1", "8", "11", "69", "96", "88", "181", "6889", "2", "7", "26", "62", "A6"}) {
    EXPECT_FALSE(readsDifferentlyUpsideDown(label)) << label;
    EXPECT_EQ(labelText(label), label);
  }
}

TEST(HersheyFont, LabelMarkIsAPeriodAfterTheNumberOnTheBaseline) {
  const auto plain = font().strokes("6", Point2(1, 1), 0.3);
  const auto marked = labelStrokes(font(), "6", Point2(1, 1), 0.3);
  ASSERT_EQ(marked.size(), plain.size() + 1);
  for (size_t s = 0; s < plain.size(); ++s) EXPECT_EQ(marked[s], plain[s]);
  const Box mark = boxOf({marked.back()}), six = boxOf(plain);
  EXPECT_GT(mark.x0, six.x1);          // after the 6
  EXPECT_NEAR(mark.y0, 1, 1e-12);      // on the baseline
  EXPECT_LT(mark.y1 - mark.y0, 0.05);  // a dot, not a character
  EXPECT_EQ(labelStrokes(font(), "69", Point2(1, 1), 0.3), font().strokes("69", Point2(1, 1), 0.3));
}

}  // namespace
}  // namespace rotafab::geometry
