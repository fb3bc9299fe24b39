// All three writers refuse a drawing they could not write faithfully, with
// one line naming the sheet, the path and what is wrong, and write nothing.

#include <gtest/gtest.h>

#include <functional>

#include "SheetFixture.h"
#include "jobs/DxfWriter.h"
#include "jobs/SvgWriter.h"
#include "toolpath/EpsWriter.h"

namespace rotafab::jobs::sheet_tests {
namespace {

struct Writer {
  const char* name;
  std::function<void(const SheetDrawing&, std::ostream&)> write;
};

const std::vector<Writer>& writers() {
  static const std::vector<Writer> all{{"eps", writeEps}, {"svg", writeSvg}, {"dxf", writeDxf}};
  return all;
}

void expectRefused(const SheetDrawing& sheet, const std::string& mentions) {
  for (const auto& writer : writers()) {
    SCOPED_TRACE(writer.name);
    std::ostringstream out;
    try {
      writer.write(sheet, out);
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(mentions), std::string::npos) << message;
      EXPECT_NE(message.find("sheet 2"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
    EXPECT_TRUE(out.str().empty()) << "wrote before refusing";
  }
}

TEST(SheetWriters, RefuseAPathOfOnePoint) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths[3].points.resize(1);
  expectRefused(sheet, "path 4 (score) has 1 point");
}

TEST(SheetWriters, RefuseAPointOffTheBed) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths[1].points[2] = Point2(33, 4);
  expectRefused(sheet, "path 2 (cut) has the point (33, 4) off the 32 x 18 in bed");
  sheet.paths[1].points[2] = Point2(3, -0.01);
  expectRefused(sheet, "off the 32 x 18 in bed");
}

TEST(SheetWriters, RefuseANonFinitePoint) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths[0].points[0].x() = std::nan("");
  expectRefused(sheet, "path 1 (cut)");
}

TEST(SheetWriters, RefuseAnOperationWithoutColour) {
  SheetDrawing sheet = sampleSheet();
  sheet.colours.erase(Operation::Etch);
  expectRefused(sheet, "no colour for etch");
}

TEST(SheetWriters, RefuseAnEmptyBed) {
  SheetDrawing sheet = sampleSheet();
  sheet.height = 0;
  expectRefused(sheet, "not a positive size");
}

TEST(SheetWriters, AcceptPointsOnTheBedsEdgeAndAnEmptySheet) {
  SheetDrawing sheet = sampleSheet();
  sheet.paths = {{Operation::Outline, {{0, 0}, {32, 0}, {32, 18}, {0, 18}}, true}};
  for (const auto& writer : writers()) {
    std::ostringstream out;
    EXPECT_NO_THROW(writer.write(sheet, out)) << writer.name;
  }
  sheet.paths.clear();
  for (const auto& writer : writers()) {
    std::ostringstream out;
    EXPECT_NO_THROW(writer.write(sheet, out)) << writer.name;
    EXPECT_FALSE(out.str().empty());
  }
}

TEST(SheetWriters, OutputDoesNotDependOnTheStreamsLocale) {
  // A German locale would write 0,5 for 0.5 through iostreams.
  const SheetDrawing sheet = sampleSheet();
  for (const auto& writer : writers()) {
    std::ostringstream plain, german;
    struct Comma : std::numpunct<char> {
      char do_decimal_point() const override { return ','; }
      char do_thousands_sep() const override { return '.'; }
      std::string do_grouping() const override { return "\3"; }
    };
    german.imbue(std::locale(german.getloc(), new Comma));
    writer.write(sheet, plain);
    writer.write(sheet, german);
    EXPECT_EQ(plain.str(), german.str()) << writer.name;
  }
}

}  // namespace
}  // namespace rotafab::jobs::sheet_tests
