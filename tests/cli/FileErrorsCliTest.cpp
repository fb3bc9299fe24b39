// Files a new user gets wrong, met through the program: a mesh saved under
// the wrong extension, an OBJ with a bad face, a file where an output folder
// should be, a folder that is not a `make` output. Each gets one line that
// names the file and says what is wrong in the file's terms (no reader
// library's words), before any work is done.

#include <gtest/gtest.h>

#include "cli/CliSupport.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

constexpr const char* kTetrahedronObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST(FileErrorsCli, MeshFilesAreDescribedInTheirOwnTerms) {
  TempDir dir;
  struct Case {
    std::string file, bytes, says;
  };
  const std::vector<Case> cases = {
      {"tetrahedron.stl", kTetrahedronObj,
       "the file is text, not STL (a text STL starts with 'solid'): it looks like OBJ; rename it to .obj"},
      {"index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\n# the last one\nf 1 4 13\n",
       "line 8: the face refers to vertex 13, but the file has 4 vertices"},
      {"wire.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3 1\n", "the file holds no polygon faces"},
      {"cloud.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "the file holds no polygon faces"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const auto path = dir.write(c.file, c.bytes);
    const CommandResult r = run(kCli + " inspect " + quoted(path));
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, "error: " + path.string() + ": " + c.says + "\n");
  }
  // Renamed as told, the same bytes are read.
  const auto renamed = dir.write("tetrahedron.obj", kTetrahedronObj);
  EXPECT_EQ(run(kCli + " inspect " + quoted(renamed)).status, 0);
}

TEST(FileErrorsCli, AnOutputFolderThatIsAFileIsRefusedBeforeAnyWork) {
  TempDir dir;
  const auto mesh = dir.write("tetrahedron.obj", kTetrahedronObj);
  const auto file = dir.write("notes.txt", "mine\n");
  for (const std::string& out : {file.string(), file.string() + "/sheets"}) {
    SCOPED_TRACE(out);
    const CommandResult r =
        run(kCli + " make " + quoted(mesh) + " --structure band --out " + quoted(std::filesystem::path(out)));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.out, "");
    // One line naming the option, then the help to read; no progress: nothing was built.
    EXPECT_TRUE(r.err.starts_with("error: --out: " + out + ": ")) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;
  }
  EXPECT_EQ(readFile(file), "mine\n");
}

TEST(FileErrorsCli, AFolderThatIsNotAMakeOutputIsNamedAsSuch) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "photos");
  const auto folder = dir.path() / "photos";
  for (const std::string verb : {"manifest", "run"}) {
    SCOPED_TRACE(verb);
    const std::string extra = verb == "run" ? " --device sim:grbl" : "";
    const CommandResult r = run(kCli + " " + verb + " " + quoted(folder) + extra);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err,
              "error: " + folder.string() + ": not an output folder of `rotafab make`: it holds no manifest.json\n");
  }
  const auto notJson = dir.write("manifest.json", "{ \"version\": 1,\n  oops }\n");
  const CommandResult r = run(kCli + " manifest " + quoted(notJson));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err.find("json.exception"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("manifest.json: not JSON: line 2"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace rotafab::test
