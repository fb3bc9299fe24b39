#pragma once
// Labels etched on a band panel (dissertation V.5, fig. 59-60): the edge
// number on each edge band, near its holes and reading along the band (out
// from the panel's vertex band), and the panel's flood-fill number on the
// vertex band. Single-stroke Hershey text (HersheyFont.h), 6 and 9 marked
// (labelText()). Each label is sized to fit: the largest capital height from
// kLargestLabel down to kSmallestLabel whose text box, kept clear of the
// cut outline, the holes and the other labels by a quarter of its height
// (at least kLabelGap), lies inside its band (or vertex band).

#include <optional>
#include <string>
#include <vector>

#include "core/LengthUnit.h"
#include "geometry/HersheyFont.h"

namespace rotafab::geometry {

constexpr double kLargestLabel = 0.25, kSmallestLabel = 0.06, kLabelGap = 0.02;  // inches

// A placed line of text: its box is `origin` + [0, width] along `direction` x [0, height] across.
struct TextBox {
  Point2 origin;
  double angle = 0;  // radians, counter-clockwise from +x
  double width = 0, height = 0;
  Point2 along{1, 0};  // must be (cos angle, sin angle): kept to spare the trigonometry in the fitting

  [[nodiscard]] std::vector<Point2> corners() const;
  // The distance from p to the box (0 inside).
  [[nodiscard]] double distanceTo(const Point2& p) const;
};

struct Circle {
  Point2 centre;
  double radius = 0;
};

// The largest box of `text` (already marked) that fits inside `region` (a
// piece of the panel, inside `outline`), clear of `outline`, of `holes` and
// of `taken`, reading along the first of `angles` at which any box fits
// (the reading the layout prefers first; the others are for a strip too
// short for the text along it), its centre tried at `candidates` in turn
// for each height, no taller than `largest`. Nothing if none fits at
// kSmallestLabel.
std::optional<TextBox> fitText(const HersheyFont& font, const std::string& text, const std::vector<double>& angles,
                               const std::vector<Point2>& region, const std::vector<Point2>& outline,
                               const std::vector<Circle>& holes, const std::vector<TextBox>& taken,
                               const std::vector<Point2>& candidates, double largest = kLargestLabel);

// A strip's readings: along `angle` first, else across it, the text's top
// toward `angle` (read from the strip's root, where the builder stands).
std::vector<double> alongThenAcross(double angle);

// The warning for labels that fit nowhere, even at kSmallestLabel (one
// list per panel, built in parallel): "N labels are not etched, too large
// for their `strip` even at 0.06 in: ..." (the height in `unit`); none when every label fits.
std::optional<std::string> unetchedLabelsWarning(const std::vector<std::vector<std::string>>& unfittedOf,
                                                 const std::string& strip, core::LengthUnit unit = {});

}  // namespace rotafab::geometry
