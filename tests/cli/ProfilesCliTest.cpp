// `rotafab profiles` through the built program: checks the files given,
// lists the search path.

#include <gtest/gtest.h>

#include "support/ProfileSamples.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

TEST(ProfilesCli, ChecksFilesAndListsTheSearchPath) {
  TempDir dir;
  const auto bad = dir.write("bad.yaml", replaced(kGoodMachine, "driver: spool", "drivr: spool"));
  const auto good = dir.write("good.yaml", kGoodMachine);
  const CommandResult refused = run(std::string(ROTAFAB_CLI) + " profiles " + bad.string());
  EXPECT_EQ(refused.status, 1);
  EXPECT_EQ(refused.err, "error: " + bad.string() +
                             ":4:1: drivr: unknown key (expected one of: kind, name, description, bed, driver, "
                             "connection, colours, operations, motion, formats, frame_power)\n");
  EXPECT_EQ(refused.out, "") << "nothing on standard output before, or instead of, the error";
  // --check FILE is the same; a bed in millimetres without its unit is named with the fix.
  const auto metric =
      dir.write("metric.yaml", replaced(kGoodMachine, "width: 32in, height: 18in", "width: 400, height: 430"));
  const CommandResult unitless = run(std::string(ROTAFAB_CLI) + " profiles --check " + metric.string());
  EXPECT_EQ(unitless.status, 1);
  EXPECT_EQ(unitless.err,
            "error: " + metric.string() +
                ":3:14: bed.width: 400 without a unit, which would be 400 inches; write 400mm or 400in\n");
  const CommandResult accepted = run(std::string(ROTAFAB_CLI) + " profiles --json " + good.string());
  EXPECT_EQ(accepted.status, 0) << accepted.err;
  EXPECT_NE(accepted.out.find(R"("name":"test")"), std::string::npos) << accepted.out;
  // From the source tree, the shipped profiles are on the search path.
  const CommandResult listed = run("cd " + std::string(ROTAFAB_SOURCE_DIR) + " && " + ROTAFAB_CLI + " profiles");
  EXPECT_EQ(listed.status, 0) << listed.err;
  EXPECT_NE(listed.out.find("workshop-32x18"), std::string::npos);
  EXPECT_NE(listed.out.find("posterboard"), std::string::npos);
}

// Each length is shown in the unit its file gives it in: a 400 mm bed is not
// "15.7 in", a 3 mm sheet not "0.1181 in"; a file in inches stays in inches.
TEST(ProfilesCli, LengthsAreShownInTheirFilesUnits) {
  const CommandResult listed = run("cd " + std::string(ROTAFAB_SOURCE_DIR) + " && " + ROTAFAB_CLI + " profiles");
  ASSERT_EQ(listed.status, 0) << listed.err;
  const auto line = [&](const std::string& name) {
    const size_t at = listed.out.find("  " + name + " ");
    return at == std::string::npos ? std::string() : listed.out.substr(at, listed.out.find('\n', at) - at);
  };
  EXPECT_NE(line("grbl-diode-400").find(" 400 x 400    mm  margin 5 mm "), std::string::npos) << line("grbl-diode-400");
  EXPECT_NE(line("workshop-32x18").find(" 32 x 18     in  margin 0.25 in "), std::string::npos)
      << line("workshop-32x18");
  EXPECT_NE(line("plywood-3mm").find(" 3 mm thick, kerf 0.15 mm, fastener 3.2 mm "), std::string::npos)
      << line("plywood-3mm");
  EXPECT_NE(line("posterboard").find(" 0.8 mm thick, kerf 0.004 in, fastener 0.125 in "), std::string::npos)
      << line("posterboard");
  // JSON keeps inches (docs/CONTRACT.md, "Units and scale"), and says which
  // unit the file used.
  const CommandResult json = run("cd " + std::string(ROTAFAB_SOURCE_DIR) + " && " + ROTAFAB_CLI + " profiles --json");
  EXPECT_NE(
      json.out.find(
          R"("bed":{"width":15.748031496062993,"height":15.748031496062993,"margin":0.19685039370078738,"unit":"mm"})"),
      std::string::npos)
      << json.out;
}

}  // namespace
}  // namespace rotafab::test
