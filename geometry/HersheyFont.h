#pragma once
// Single-stroke text for etched labels: a Hershey font read from Debian's
// hershey-fonts-data (.jhf files, James Hurt's format), turned into polylines
// that a laser follows once. Outline fonts would be traced twice (both sides
// of every stroke) and need filling; a stroke font is what the "single-stroke
// labels" of docs/CONTRACT.md ("Layout") need.
//
// The .jhf format: one record per glyph, "IIIIINNNLR" then pairs: a 5-column
// glyph number, a 3-column count of pairs (the bounds pair included), the
// glyph's left and right bounds, then its vertices. Each coordinate is one
// character, its value the character's code minus 'R'; y grows downwards;
// the pair " R" lifts the pen. A record may be wrapped over several lines.
//
// ASCII mapping: the ASCII-ordered files of the package hold exactly 96
// records, the k-th (from 0) being the glyph of character code 32 + k, i.e.
// space to '~' and a last one in the place of DEL. Their glyph-number column
// does not say this (futural.jhf has 12345 everywhere; rowmans.jhf has
// Hershey's own numbers: 699 for space, 501-526 for A-Z, 601-626 for a-z,
// 700-709 for 0-9), so the order of the records is the mapping. Text may
// use the printable characters ' ' to '~'; anything else (control characters,
// DEL, bytes of non-ASCII UTF-8) is refused with std::invalid_argument naming
// the character and its position, rather than being etched as something else.
//
// The default font is rowmans.jhf, Hershey's Simplex Roman in ASCII order. It
// is preferred to futural.jhf, otherwise the same strokes, because futural's
// '.', ',', ':' and ';' sit three units above the baseline, and labelText()
// below relies on a period that sits on it.
//
// Scale: `height` is the capital height. Hershey's Roman fonts put the top of
// the capitals and digits at y = -12 and the baseline at y = 9, so one font
// unit is height / 21. Advance widths are the glyphs' right minus left bounds
// (side bearings included, as Hershey designed them).

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rotafab::geometry {

using Point2 = Eigen::Vector2d;  // as in SheetDrawing.h: inches
using Polyline = std::vector<Point2>;

class HersheyFont {
 public:
  // Reads a .jhf file; a malformed one is refused with std::runtime_error
  // "FILE:LINE: what is wrong".
  static HersheyFont load(const std::filesystem::path& file);

  // Simplex Roman (rowmans.jhf), read once: from the fonts installed beside
  // the program (PREFIX/share/rotafab/fonts), else from kDefaultFontFolder,
  // where Debian's hershey-fonts-data puts them.
  static const HersheyFont& simplex();
  static constexpr const char* kDefaultFontFolder = "/usr/share/hershey-fonts";

  int glyphCount() const { return static_cast<int>(glyphs_.size()); }

  // The strokes of `text` set on a baseline that starts at `origin` and reads
  // along the direction `angleRadians` (counter-clockwise from +x, y up), with
  // capitals `height` tall; one polyline of at least 2 points per pen-down
  // stroke, in inches. Spaces advance but draw nothing.
  std::vector<Polyline> strokes(std::string_view text, Point2 origin, double height, double angleRadians = 0) const;

  // The advance width of `text` along its baseline, in the same units as
  // `height`.
  double advance(std::string_view text, double height) const;

 private:
  struct Glyph {
    int left = 0, right = 0;                            // bounds, font units
    std::vector<std::vector<Eigen::Vector2i>> strokes;  // font units, y down
  };
  const Glyph& glyphFor(std::string_view text, size_t position) const;
  static double unitsToInches(double height);

  std::vector<Glyph> glyphs_;
};

// Numbers on panels are read from any side, so a label that reads as another
// label upside down (rotated by 180 degrees) gets a mark. Digits that read as
// digits upside down: 0, 1 and 8 as themselves, 6 and 9 as each other. A
// label is marked exactly when it is made only of these digits and its
// upside-down reading differs from it: "6", "9", "16" (upside down "91"),
// "10" ("01"), but not "8", "11", "69" (which reads "69" either way) or "27"
// (which reads as no number upside down).
bool readsDifferentlyUpsideDown(std::string_view label);

// The mark is a period after the label, as in "6." and "9.": upside down it
// stands before the number at the top, where no period goes. (A period rather
// than an underline, because docs/CONTRACT.md ("What Rotafab is") already
// gives the underline a meaning: the neighbouring edge index of a woven
// panel.)
std::string labelText(std::string_view label);

// font.strokes(labelText(label), ...).
std::vector<Polyline> labelStrokes(const HersheyFont& font, std::string_view label, Point2 origin, double height,
                                   double angleRadians = 0);

}  // namespace rotafab::geometry
