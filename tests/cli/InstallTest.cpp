// `cmake --install`: the program, its helper, the profiles and the label font
// go under any prefix, and the installed program finds them there, from any
// folder (an installed program does not look in the source tree).

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

TEST(Install, TheInstalledProgramFindsItsProfilesFontAndHelper) {
  TempDir dir;
  const auto prefix = dir.path() / "prefix";
  const CommandResult installed = run("cmake --install " + quoted(ROTAFAB_BUILD_DIR) + " --prefix " + quoted(prefix));
  ASSERT_EQ(installed.status, 0) << installed.err;
  for (const char* file : {"bin/rotafab", "libexec/rotafab/rotafab-sim-m2nano", "libexec/rotafab/rotafab-read-mesh",
                           "share/rotafab/profiles/machines/workshop-32x18.yaml",
                           "share/rotafab/profiles/materials/posterboard.yaml", "share/rotafab/fonts/rowmans.jhf"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(prefix / file)) << file;
  }
  // From a folder with no profiles of its own: every shipped profile is the installed one.
  const std::string cli = quoted(prefix / "bin/rotafab");
  const std::string in = "cd " + quoted(dir.path()) + " && ";
  const CommandResult listed = run(in + cli + " profiles --json");
  ASSERT_EQ(listed.status, 0) << listed.err;
  const auto profiles = nlohmann::json::parse(listed.out);
  for (const char* kind : {"machines", "materials"}) {
    ASSERT_FALSE(profiles.at(kind).empty());
    for (const auto& p : profiles.at(kind)) {
      EXPECT_EQ(p.at("file").get<std::string>().rfind((prefix / "share/rotafab/profiles").string(), 0), 0u) << p.dump();
    }
  }
  // It builds (the labels are etched in the installed font) and cuts on the simulated M2 Nano (the installed helper).
  const CommandResult made =
      run(in + cli + " make " + quoted(std::filesystem::path(ROTAFAB_SOURCE_DIR) / "examples/cube.obj") +
          " --structure band --machine k40-m2nano --size 4in --time 0 --out cube");
  ASSERT_EQ(made.status, 0) << made.err;
  const CommandResult cut = run(in + cli + " run cube --sheet 1 --device 'sim:m2nano?speed=2000'");
  EXPECT_EQ(cut.status, 0) << cut.err;
  EXPECT_NE(cut.out.find("1 sheet cut on sim:m2nano"), std::string::npos) << cut.out;
}

}  // namespace
}  // namespace rotafab::test
