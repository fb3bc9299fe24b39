// `rotafab nest` through the built program: the summary and layout.json of
// docs/CONTRACT.md ("nest"), and one-line refusals of bad instance files.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli/CliSupport.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

TEST(NestCli, StripRunWritesLayoutAndSummary) {
  TempDir dir;
  const auto instance = dir.write(
      "parts.json",
      R"({"name":"t","strip_height":10,"items":[)"
      R"({"id":0,"demand":3,"allowed_orientations":[0,90],"shape":{"type":"simple_polygon","data":[[0,0],[4,0],[4,1],[1,1],[1,3],[0,3],[0,0]]}},)"
      R"({"id":7,"demand":2,"allowed_orientations":[0],"shape":{"type":"simple_polygon","data":[[0,0],[2,0],[1,2]]}}]})");
  const CommandResult result =
      run(kCli + " nest " + instance.string() + " --strip --time 0.2 --json --out " + (dir.path() / "out").string());
  ASSERT_EQ(result.status, 0) << result.err;
  const auto summary = nlohmann::json::parse(result.out);
  EXPECT_EQ(summary["sheets"], 1);
  EXPECT_TRUE(summary["utilization"].is_null());
  EXPECT_GT(summary["density"].get<double>(), 0.1);
  EXPECT_LE(summary["density"].get<double>(), 1.0);
  const double area = 3 * 6.0 + 2 * 2.0;
  EXPECT_NEAR(summary["density"].get<double>(), area / (10 * summary["strip_length"].get<double>()), 1e-9);
  const auto layout = nlohmann::json::parse(readFile(dir.path() / "out" / "layout.json"));
  ASSERT_EQ(layout["placements"].size(), 5u);
  std::multiset<int> items;
  int cut = 0;
  for (const auto& p : layout["placements"]) {
    items.insert(p["item"].get<int>());
    EXPECT_EQ(p["sheet"], 1);
    // Copies are numbered in file order: item 0's three, then item 7's two.
    const int order = p["item"] == 0 ? p["copy"].get<int>() : 3 + p["copy"].get<int>();
    EXPECT_EQ(p["moved"], cut++ - order);
  }
  EXPECT_EQ(items.count(0), 3u);
  EXPECT_EQ(items.count(7), 2u);
  EXPECT_NE(readFile(dir.path() / "out" / "layout.svg").find("<svg"), std::string::npos);
}

TEST(NestCli, BinRunUsesTheWorkshopBedByDefault) {
  TempDir dir;
  const auto instance = dir.write(
      "parts.json",
      R"({"items":[{"id":1,"demand":4,"shape":{"type":"simple_polygon","data":[[0,0],[20,0],[20,10],[0,10]]}}]})");
  const CommandResult result = run(kCli + " nest " + instance.string() + " --time 0 --json");
  ASSERT_EQ(result.status, 0) << result.err;
  const auto summary = nlohmann::json::parse(result.out);
  EXPECT_EQ(summary["sheets"], 4) << "a 20 x 10 part fits once on a 31.5 x 17.5 usable bed";
  EXPECT_NEAR(summary["utilization"].get<double>(), 200.0 / (31.5 * 17.5), 1e-9);
}

// --bed 800x600mm is 800 mm by 600 mm, 31.5 x 23.6 in (a 15 x 11 in part
// fits twice across and twice up, 4 to a bed: 12 take 3 beds; read as 800
// in by 600 mm, one would do), the same as 800mmx600mm; a unit on the first
// number only is refused, not guessed.
TEST(NestCli, ABedUnitAtTheEndIsBothSides) {
  TempDir dir;
  const auto instance = dir.write(
      "parts.json",
      R"({"items":[{"id":1,"demand":12,"shape":{"type":"simple_polygon","data":[[0,0],[15,0],[15,11],[0,11]]}}]})");
  for (const char* bed : {"800x600mm", "800mmx600mm", "80cmx600mm"}) {
    const CommandResult result = run(kCli + " nest " + instance.string() + " --margin 0 --time 0 --json --bed " + bed);
    ASSERT_EQ(result.status, 0) << bed << ": " << result.err;
    EXPECT_EQ(nlohmann::json::parse(result.out)["sheets"], 3) << bed;
  }
  const CommandResult guessed = run(kCli + " nest " + instance.string() + " --time 0 --bed 800mmx600");
  EXPECT_EQ(guessed.status, 1);
  EXPECT_NE(guessed.err.find("--bed 800mmx600: expected WIDTHxHEIGHT, a unit once at the end"), std::string::npos)
      << guessed.err;
}

TEST(NestCli, BadInstancesAreOneLineNamingTheElement) {
  TempDir dir;
  struct Case {
    const char* json;
    std::string message;
  };
  const Case cases[] = {
      {R"({"items":[{"id":1,"shape":{"type":"simple_polygon","data":[[0,0],[1,0]]}}]})",
       "items[0].shape.data: expected a polygon of at least 3 points with area"},
      {R"({"items":[{"id":1,"demand":0,"shape":{"type":"simple_polygon","data":[[0,0],[1,0],[0,1]]}}]})",
       "items[0].demand: expected a whole number from 1"},
      {R"({"items":[{"id":1,"shape":{"type":"simple_polygon","data":[[0,0],[1,"x"],[0,1]]}}]})",
       "items[0].shape.data[1]: expected [x, y]"},
      {R"({"items":[{"id":1,"shape":{"type":"simple_polygon","data":[[0,0],[40,0],[40,1]]}}]})",
       "item 1 copy 1 (40 x 1) does not fit the usable area of 31.5 x 17.5 in any allowed rotation"},
      {R"({"things":[]})", "items: expected an object with an \"items\" list"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.json);
    const auto instance = dir.write("bad.json", c.json);
    const CommandResult result = run(kCli + " nest " + instance.string() + " --time 0");
    EXPECT_EQ(result.status, 1);
    EXPECT_EQ(result.err, "error: " + instance.string() + ": " + c.message + "\n");
  }
  const CommandResult usage = run(kCli + " nest x.json --order sideways");
  EXPECT_EQ(usage.status, 2);
}

}  // namespace
}  // namespace rotafab::test
