// `rotafab inspect` through the built program: the JSON and exit statuses of
// docs/CONTRACT.md ("inspect", "Command line"), and one-line errors, on our
// examples and on meshes we did not make.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli/CliSupport.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

nlohmann::json inspectJson(const std::filesystem::path& mesh) {
  const CommandResult result = run(kCli + " inspect --json '" + mesh.string() + "'");
  EXPECT_EQ(result.status, 0) << result.err;
  return nlohmann::json::parse(result.out);
}

TEST(InspectCli, ExamplesGiveSpecJsonInSpecOrderThenTheProblems) {
  struct Case {
    const char* file;
    const char* json;
  };
  const Case cases[] = {
      {"bunny.obj",
       R"({"vertices":1839,"edges":5511,"faces":3674,"boundary_loops":0,"components":1,"euler":2,"genus":0,"orientable":true,"manifold":true,"usable":true,"problems":[],"repaired":[]})"},
      {"soccer-ball.obj",
       R"({"vertices":60,"edges":90,"faces":32,"boundary_loops":0,"components":1,"euler":2,"genus":0,"orientable":true,"manifold":true,"usable":true,"problems":[],"repaired":[]})"},
      {"torus.obj",
       R"({"vertices":288,"edges":576,"faces":288,"boundary_loops":0,"components":1,"euler":0,"genus":1,"orientable":true,"manifold":true,"usable":true,"problems":[],"repaired":[]})"},
      {"genus2.obj",
       R"({"vertices":48,"edges":100,"faces":50,"boundary_loops":0,"components":1,"euler":-2,"genus":2,"orientable":true,"manifold":true,"usable":true,"problems":[],"repaired":[]})"},
      {"cube.obj",
       R"({"vertices":8,"edges":12,"faces":6,"boundary_loops":0,"components":1,"euler":2,"genus":0,"orientable":true,"manifold":true,"usable":true,"problems":[],"repaired":[]})"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const CommandResult result = run(kCli + " inspect --json " + (kSource / "examples" / c.file).string());
    EXPECT_EQ(result.status, 0) << result.err;
    EXPECT_EQ(result.out, std::string(c.json) + "\n");
  }
}

TEST(InspectCli, TextFormIsForPeople) {
  const CommandResult result = run(kCli + " inspect " + (kSource / "examples" / "genus2.obj").string());
  EXPECT_EQ(result.status, 0);
  EXPECT_NE(result.out.find("genus           2"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("50 quads"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("usable for `rotafab make`"), std::string::npos);
}

TEST(InspectCli, BrokenButReadableMeshIsReportedWithExitZero) {
  TempDir dir;
  const auto mesh = dir.write("fin.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  const CommandResult json = run(kCli + " inspect --json " + mesh.string());
  EXPECT_EQ(json.status, 0);
  const auto object = nlohmann::json::parse(json.out);
  EXPECT_EQ(object["manifold"], false);
  EXPECT_TRUE(object["genus"].is_null());
  EXPECT_EQ(object["usable"], false);
  const CommandResult text = run(kCli + " inspect " + mesh.string());
  EXPECT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("edge (0, 1) is shared by 3 faces (0, 1, 2)"), std::string::npos) << text.out;
  // The JSON lists the problems the text prints, each with its kind.
  ASSERT_EQ(object["problems"].size(), 1u) << json.out;
  EXPECT_EQ(object["problems"][0]["kind"], "non-manifold-edge");
  EXPECT_NE(text.out.find("  " + object["problems"][0]["message"].get<std::string>() + "\n"), std::string::npos);
}

TEST(InspectCli, UnreadableMeshIsOneLineAndExitOne) {
  TempDir dir;
  const auto mesh = dir.write("cut.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n");
  const CommandResult result = run(kCli + " inspect " + mesh.string());
  EXPECT_EQ(result.status, 1);
  EXPECT_EQ(result.out, "");
  EXPECT_EQ(result.err,
            "error: " + mesh.string() + ": truncated: the header states 4 vertices, the file ends after 2\n");
}

TEST(InspectCli, UsageErrorsExitTwo) {
  for (const char* args : {"", " inspect", " inspect a.obj --bogus", " frobnicate"}) {
    SCOPED_TRACE(args);
    const CommandResult result = run(kCli + args);
    EXPECT_EQ(result.status, 2) << result.err;
    EXPECT_NE(result.err.find("error: "), std::string::npos);
  }
  const CommandResult help = run(kCli + " inspect --help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("rotafab inspect examples/bunny.obj"), std::string::npos) << "help shows a working example";
}

TEST(InspectCli, WarningsGoToStandardErrorAndJsonStaysClean) {
  TempDir dir;
  const auto mesh = dir.write("extra.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n5 5 5\n3 0 1 2\n");
  const CommandResult result = run(kCli + " inspect --json " + mesh.string());
  EXPECT_EQ(result.status, 0);
  EXPECT_EQ(nlohmann::json::parse(result.out)["vertices"], 3);
  EXPECT_EQ(result.err, "warning: " + mesh.string() + ": dropped 1 unreferenced vertex\n");
}

TEST(InspectCli, RepairedOrientationIsSaidInBothForms) {
  TempDir dir;
  // A tetrahedron with its last face wound the wrong way.
  const auto mesh =
      dir.write("tet.off", "OFF\n4 4 0\n1 1 1\n1 -1 -1\n-1 1 -1\n-1 -1 1\n3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 2 3\n");
  const CommandResult json = run(kCli + " inspect --json " + mesh.string());
  EXPECT_EQ(json.status, 0);
  EXPECT_EQ(nlohmann::json::parse(json.out)["orientable"], true);
  EXPECT_NE(json.err.find("note: " + mesh.string() + ": flipped 1 face to make the orientation consistent"),
            std::string::npos)
      << json.err;
  const CommandResult text = run(kCli + " inspect " + mesh.string());
  EXPECT_NE(text.out.find("repaired: flipped 1 face to make the orientation consistent"), std::string::npos)
      << text.out;
}

// Meshes from other public sources (tests/data/external/README.md): the
// counts an independent checker (tools/meshcheck.py) computed. Where rotafab
// deliberately differs, the entry's rotafab_expected gives our values and why.
void expectMatchesChecker(const nlohmann::json& entry, const std::filesystem::path& path) {
  SCOPED_TRACE(path.string());
  ASSERT_TRUE(std::filesystem::exists(path)) << "install it with scripts/setup.sh (package " << entry["package"] << ")";
  nlohmann::json expected = entry["expected"];
  if (entry.contains("rotafab_expected")) {
    for (const auto& [key, value] : entry["rotafab_expected"].items())
      if (key != "why") expected[key] = value;
  }
  const auto actual = inspectJson(path);
  for (const auto& [key, value] : expected.items()) EXPECT_EQ(actual[key], value) << key;
}

TEST(InspectCli, ExternalMeshesMatchTheIndependentChecker) {
  const auto meshes = nlohmann::json::parse(readFile(kSource / "tests/data/external/meshes.json"));
  ASSERT_GE(meshes.size(), 20u);
  for (const auto& entry : meshes) {
    std::filesystem::path path = entry["path"].get<std::string>();
    expectMatchesChecker(entry, path.is_relative() ? kSource / path : path);
  }
}

// CGAL's data sets (OFF files CGAL wrote, with comment lines) come inside a tarball.
TEST(InspectCli, CgalMeshesMatchTheIndependentChecker) {
  const auto meshes = nlohmann::json::parse(readFile(kSource / "tests/data/external/meshes-cgal.json"));
  ASSERT_GE(meshes.size(), 10u);
  for (const auto& entry : meshes) {
    const std::string archive = entry["archive"], member = entry["member"];
    expectMatchesChecker(entry, publicMesh(archive + ":" + member));
  }
}

}  // namespace
}  // namespace rotafab::test
