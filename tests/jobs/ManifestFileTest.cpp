// The two readers of a manifest agree: readManifestSheets (simdjson, what
// the daemon reads on every submission of a folder) lists the same SVG
// sheets, panels and cost as readManifest, on a folder `make` wrote; and a
// manifest that is not as `make` writes it is left to readManifest, which
// says what is wrong.

#include "toolpath/ManifestFile.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/UserError.h"
#include "jobs/MakeJob.h"
#include "support/TestContext.h"
#include "support/TestSupport.h"
#include "support/WorkshopRequest.h"
#include "toolpath/JobSheets.h"

namespace rotafab::jobs {
namespace {

const std::filesystem::path kManifestTestSource = ROTAFAB_SOURCE_DIR;

std::filesystem::path madeCube(const std::filesystem::path& dir) {
  const auto out = dir / "cube";
  makeJob(test::workshopRequest(kManifestTestSource / "examples/cube.obj"), out, test::context());
  return out;
}

void writeManifestText(const std::filesystem::path& file, const std::string& text) { std::ofstream(file) << text; }

TEST(ManifestFile, TheFastReaderListsWhatTheFullReaderReads) {
  test::TempDir dir;
  const auto folder = madeCube(dir.path());
  const auto full = readManifest(folder);
  const auto fast = readManifestSheets(folder / "manifest.json");
  ASSERT_TRUE(fast.has_value());

  std::vector<std::pair<int, std::string>> listed;
  for (const auto& sheet : full.at("sheets")) {
    for (const auto& file : sheet.at("files")) {
      const std::string name = file;
      if (name.ends_with(".svg")) listed.emplace_back(sheet.at("index").get<int>(), name);
    }
  }
  ASSERT_FALSE(listed.empty());
  EXPECT_EQ(fast->svgSheets, listed);
  ASSERT_TRUE(fast->panels.has_value());
  EXPECT_EQ(*fast->panels, full.at("panels").size());
  ASSERT_TRUE(fast->cost.has_value());
  EXPECT_EQ(nlohmann::json::parse(*fast->cost), nlohmann::json(full.at("cost")));

  // The sheets read from either list are the same drawings.
  const auto viaFull = readJobSheets(folder, full);
  const auto viaFast = readJobSheets(folder, fast->svgSheets);
  ASSERT_EQ(viaFast.size(), viaFull.size());
  for (size_t i = 0; i < viaFast.size(); ++i) {
    EXPECT_EQ(viaFast[i].index, viaFull[i].index);
    EXPECT_EQ(viaFast[i].file, viaFull[i].file);
    EXPECT_EQ(viaFast[i].drawing.width, viaFull[i].drawing.width);
    EXPECT_EQ(viaFast[i].drawing.paths.size(), viaFull[i].drawing.paths.size());
  }
}

TEST(ManifestFile, AManifestNotAsMakeWritesItIsLeftToTheFullReader) {
  test::TempDir dir;
  const auto manifest = dir.path() / "manifest.json";
  for (const std::string& text : {
           std::string("{\"sheets\": [{\"index\": 1, \"files\": [\"sheet-001.svg\"]}"),  // cut short
           std::string("[1, 2]"),                                                        // not an object
           std::string("{\"version\": 1}"),                                              // no sheets
           std::string("{\"sheets\": [{\"index\": \"1\", \"files\": [\"sheet-001.svg\"]}]}"),
           std::string("{\"sheets\": [{\"index\": 1, \"files\": \"sheet-001.svg\"}]}"),
           std::string("{\"sheets\": [{\"index\": 1, \"files\": [7]}]}"),
           std::string("{\"sheets\": [{\"index\": 4294967297, \"files\": [\"sheet-001.svg\"]}]}"),
           std::string("{\"sheets\": [{\"index\": 0, \"files\": [\"sheet-001.svg\"]}]}"),
       }) {
    writeManifestText(manifest, text);
    EXPECT_FALSE(readManifestSheets(manifest).has_value()) << text;
  }
  EXPECT_FALSE(readManifestSheets(dir.path() / "missing.json").has_value());
  // ... and the full reader refuses a sheet number out of range (it wrapped 4294967297 to 1).
  writeManifestText(manifest, R"({"sheets": [{"index": 4294967297, "files": ["sheet-001.svg"]}]})");
  try {
    readJobSheets(dir.path(), std::nullopt);
    FAIL() << "read";
  } catch (const core::UserError& error) {
    EXPECT_NE(std::string(error.what()).find("index 4294967297 is not a sheet's number"), std::string::npos)
        << error.what();
  }

  // A manifest that lists no SVG is read, and refused by the sheets' reader in the words of the full one.
  writeManifestText(manifest, R"({"sheets": [{"index": 1, "files": ["sheet-001.eps"]}]})");
  const auto fast = readManifestSheets(manifest);
  ASSERT_TRUE(fast.has_value());
  EXPECT_TRUE(fast->svgSheets.empty());
  EXPECT_FALSE(fast->panels.has_value());
  try {
    readJobSheets(dir.path(), fast->svgSheets);
    FAIL() << "read";
  } catch (const core::UserError& error) {
    EXPECT_NE(std::string(error.what()).find("manifest.json: lists no SVG sheet"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace rotafab::jobs
