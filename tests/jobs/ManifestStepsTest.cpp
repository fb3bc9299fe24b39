// The assembly steps read back from manifest.json (jobs/Manifest.h): how
// each kind of piece cut off a panel is put on, and a band with no room for
// a fastener, in the words the builders follow. The manifest is written by
// hand here, so that each case is there whatever the geometry makes today.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "jobs/Manifest.h"

namespace rotafab::jobs {
namespace {

// Three panels: panel 1's copy of band 1 cut across its middle (its far
// half the piece 1a, on sheet 2, with one of the band's two holes); panel
// 2 with a piece cut off and its tab glued (2a) and a piece fastened at its
// tab (2b); panel 3 joined to panel 2 at edge 3, a band with no holes.
const char* kManifest = R"({
  "structure": "band", "fasteners": 3, "sheets": [{}, {}],
  "panels": [
    {"id": 1, "sheet": 1, "neighbors": [2], "edges": [1], "holes": [{"edge": 1}],
     "pieces": [{"name": "1a", "edge": 1, "sheet": 2, "fastened": "band", "holes": [{"edge": 1}]}]},
    {"id": 2, "sheet": 1, "neighbors": [1, 3], "edges": [1, 3], "holes": [{"edge": 1}, {"edge": 1}, {"edge": 0}],
     "pieces": [{"name": "2a", "edge": 4, "sheet": 1, "fastened": "glue", "holes": [{"edge": 4}]},
                {"name": "2b", "edge": 5, "sheet": 2, "holes": [{"edge": 5}, {"edge": 0}]}]},
    {"id": 3, "sheet": 2, "neighbors": [2], "edges": [3], "holes": []}
  ]
})";

TEST(ManifestSteps, EachPieceAndGluedBandIsPutOnAsItIsHeld) {
  const std::string text = manifestText(nlohmann::json::parse(kManifest));
  EXPECT_NE(text.find("step    1: panel 1 (sheet 1): start here, the base\n"), std::string::npos) << text;
  // A tab glued comes first, like a tab fastened; the cut half goes on with the join of its edge.
  EXPECT_NE(text.find("step    2: panel 2 (sheet 1): first fasten piece 2b (sheet 2) to it at its tab; first glue "
                      "piece 2a (sheet 1) to it by its tab; join to panel 1 at edge 1 (2 fasteners, through piece "
                      "1a (sheet 2), the cut half of the band)\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("step    3: panel 3 (sheet 2): join to panel 2 at edge 3 (glue it: no room for a fastener)\n"),
            std::string::npos)
      << text;
  // The tab fastened is one, the join at edge 1 two; glue is none.
  EXPECT_NE(text.find("\n3 fasteners in all\n"), std::string::npos) << text;
}

// A manifest from before pieces said how they are held: every piece is fastened at its tab.
TEST(ManifestSteps, APieceWithoutFastenedIsFastenedAtItsTab) {
  nlohmann::json manifest = nlohmann::json::parse(kManifest);
  for (auto& panel : manifest["panels"]) {
    if (!panel.contains("pieces")) continue;
    for (auto& piece : panel["pieces"]) piece.erase("fastened");
  }
  const std::string text = manifestText(manifest);
  EXPECT_NE(text.find("first fasten piece 1a (sheet 2) to it at its tab; start here"), std::string::npos) << text;
  EXPECT_NE(text.find("first fasten piece 2a (sheet 1) to it at its tab; first fasten piece 2b"), std::string::npos)
      << text;
}

}  // namespace
}  // namespace rotafab::jobs
