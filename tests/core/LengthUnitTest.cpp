#include "core/LengthUnit.h"

#include <gtest/gtest.h>

namespace rotafab::core {
namespace {

// Inches, or millimetres a decimal coarser (25.4 times finer a unit), with
// no trailing zeros: what the summary and manifest.txt print.
TEST(LengthUnit, LengthsInInchesOrMillimetres) {
  const LengthUnit in = LengthUnit::inches(), mm = LengthUnit::millimetres();
  EXPECT_EQ(in(19.734, 2), "19.73 in");
  EXPECT_EQ(mm(19.734, 2), "501.2 mm");
  EXPECT_EQ(in(0.125, 3), "0.125 in");
  EXPECT_EQ(mm(0.125, 3), "3.18 mm");
  EXPECT_EQ(in.size(32, 18), "32 x 18 in");
  EXPECT_EQ(mm.size(32, 18), "812.8 x 457.2 mm");
  EXPECT_EQ(mm.size(150 / 25.4, 150 / 25.4, 142 / 25.4, 1), "150 x 150 x 142 mm");
  EXPECT_EQ(in(-0.0001, 2), "0 in");
  EXPECT_EQ(LengthUnit::named("mm"), mm);
  EXPECT_EQ(LengthUnit::named("in"), in);
  EXPECT_FALSE(LengthUnit::named("cm").has_value());
  EXPECT_EQ(LengthUnit(), in);
}

// An option's value a message suggests: rounded the way that still works
// (a size up, a fastener down), the unit written on as the user would type it.
TEST(LengthUnit, SuggestedValuesRoundTheWayThatStillWorks) {
  const LengthUnit in = LengthUnit::inches(), mm = LengthUnit::millimetres();
  EXPECT_EQ(in.value(91.2, 0, 1), "92in");
  EXPECT_EQ(mm.value(91.2, 0, 1), "2317mm");  // 2316.48 mm, up
  EXPECT_EQ(in.value(92.0000001, 0, 1), "92in");
  EXPECT_EQ(in.value(0.9229, 3, -1), "0.922in");
  EXPECT_EQ(mm.value(0.9229, 3, -1), "23.44mm");  // 23.4417 mm, down
  EXPECT_EQ(mm.value(36, 2), "914.4mm");
  EXPECT_EQ(in.value(36, 2), "36in");
}

}  // namespace
}  // namespace rotafab::core
