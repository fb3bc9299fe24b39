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
                             "connection, colours, operations)\n");
  EXPECT_EQ(refused.out, "") << "nothing on standard output before, or instead of, the error";
  const CommandResult accepted = run(std::string(ROTAFAB_CLI) + " profiles --json " + good.string());
  EXPECT_EQ(accepted.status, 0) << accepted.err;
  EXPECT_NE(accepted.out.find(R"("name":"test")"), std::string::npos) << accepted.out;
  // From the source tree, the shipped profiles are on the search path.
  const CommandResult listed = run("cd " + std::string(ROTAFAB_SOURCE_DIR) + " && " + ROTAFAB_CLI + " profiles");
  EXPECT_EQ(listed.status, 0) << listed.err;
  EXPECT_NE(listed.out.find("workshop-32x18"), std::string::npos);
  EXPECT_NE(listed.out.find("posterboard"), std::string::npos);
}

}  // namespace
}  // namespace rotafab::test
