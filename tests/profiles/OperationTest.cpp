// Operation names are what profiles (YAML keys) and SVG group ids use.

#include "profiles/Operation.h"

#include <gtest/gtest.h>

namespace rotafab::profiles {
namespace {

TEST(Operation, NamesRoundTrip) {
  EXPECT_EQ(operationName(Operation::Cut), "cut");
  EXPECT_EQ(operationName(Operation::Score), "score");
  EXPECT_EQ(operationName(Operation::Etch), "etch");
  EXPECT_EQ(operationName(Operation::Outline), "outline");
  for (Operation operation : kAllOperations) EXPECT_EQ(operationNamed(operationName(operation)), operation);
}

TEST(Operation, UnknownNamesAreNotGuessed) {
  EXPECT_EQ(operationNamed("Cut"), std::nullopt);
  EXPECT_EQ(operationNamed("cut "), std::nullopt);
  EXPECT_EQ(operationNamed(""), std::nullopt);
  EXPECT_EQ(operationNamed("engrave"), std::nullopt);
}

}  // namespace
}  // namespace rotafab::profiles
