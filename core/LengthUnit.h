#pragma once
// The unit lengths are shown to people in (docs/CONTRACT.md, "Units and
// scale"): inches or millimetres. Inside, every length stays in inches; this
// only writes them, in the summary, manifest.txt, the progress lines, the
// messages and the page.

#include <optional>
#include <string>
#include <string_view>

namespace rotafab::core {

class LengthUnit {
 public:
  // Inches, the default.
  constexpr LengthUnit() = default;
  static constexpr LengthUnit inches() { return LengthUnit(false); }
  static constexpr LengthUnit millimetres() { return LengthUnit(true); }
  // "in" or "mm"; nullopt for any other name.
  static std::optional<LengthUnit> named(std::string_view name);

  // "in" or "mm".
  [[nodiscard]] std::string_view name() const { return millimetres_ ? "mm" : "in"; }
  [[nodiscard]] bool metric() const { return millimetres_; }
  // How many of this unit make an inch.
  [[nodiscard]] double perInch() const { return millimetres_ ? 25.4 : 1.0; }

  // `inches` as a number in this unit, rounded to `inchDecimals` decimals in
  // inches and one fewer in millimetres (25.4 times finer), trailing zeros
  // dropped: number(19.734, 2) is "19.73" in inches, "501.2" in millimetres.
  [[nodiscard]] std::string number(double inches, int inchDecimals = 2) const;
  // As an option's value, the unit written on: "92in", "2337mm"; rounded up
  // when `direction` is positive, down when it is negative (a size or a
  // fastener that is tried), else to nearest.
  [[nodiscard]] std::string value(double inches, int inchDecimals, int direction = 0) const;
  // The number and the unit's name: "19.73 in", "501.2 mm"; rounded up or
  // down by `direction` as value() is.
  [[nodiscard]] std::string operator()(double inches, int inchDecimals = 2, int direction = 0) const;
  // A size: "32 x 18 in", "812.8 x 457.2 mm".
  [[nodiscard]] std::string size(double width, double height, int inchDecimals = 3) const;
  // Three sides: "5.9 x 5.9 x 5.6 in", "150 x 150 x 142 mm".
  [[nodiscard]] std::string size(double x, double y, double z, int inchDecimals) const;

  friend bool operator==(LengthUnit, LengthUnit) = default;

 private:
  constexpr explicit LengthUnit(bool millimetres) : millimetres_(millimetres) {}
  // The number alone, rounded as value() says.
  [[nodiscard]] std::string digits(double inches, int inchDecimals, int direction) const;
  bool millimetres_ = false;
};

}  // namespace rotafab::core
