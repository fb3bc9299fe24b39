// The options of `make` in one table: what the daemon reads from a
// submission's JSON is what the command line reads from its words.

#include "jobs/MakeOptions.h"

#include <gtest/gtest.h>

#include "core/UserError.h"

namespace rotafab::jobs {
namespace {

using nlohmann::json;

// The message of the OptionError `call` throws; empty when it throws none.
template <typename Call>
std::string refusal(Call&& call) {
  try {
    call();
  } catch (const OptionError& error) {
    return error.what();
  }
  return "";
}

TEST(MakeOptions, AnObjectAndTheWordsOfTheCommandLineAreTheSameOptions) {
  const MakeOptions fromObject = submittedOptions(json::parse(
      R"({"structure": "weave", "size": "30in", "panels": 300, "width": "0.5", "time": 2.5, "order": "strict"})"));
  const MakeOptions fromWords = submittedOptions(json{"--structure", "weave", "--size=30in", "--panels", "300",
                                                      "--width", "0.5", "--time", "2.5", "--order", "strict"});
  for (const MakeOptions* options : {&fromObject, &fromWords}) {
    EXPECT_EQ(options->structure, "weave");
    EXPECT_EQ(options->size, "30in");
    EXPECT_EQ(options->panels, 300);
    EXPECT_EQ(options->width, 0.5);
    EXPECT_EQ(options->seconds, 2.5);
    EXPECT_EQ(options->machine, "workshop-32x18");  // not given: the default
    EXPECT_EQ(options->given, (std::set<std::string>{"structure", "size", "panels", "width", "time", "order"}));
  }
  // Kept as JSON and shown as words, in the table's order, and read back the same.
  EXPECT_EQ(optionsJson(fromWords), optionsJson(fromObject));
  EXPECT_EQ(optionWords(fromObject),
            (std::vector<std::string>{"--structure", "weave", "--size", "30in", "--panels", "300", "--width", "0.5",
                                      "--time", "2.5", "--order", "strict"}));
  EXPECT_EQ(optionsJson(submittedOptions(optionsJson(fromObject))), optionsJson(fromObject));
  const MakeOptions band = submittedOptions(json{{"structure", "band"}, {"score-folds", true}, {"tension", 0.3}});
  EXPECT_TRUE(band.scoreFolds);
  EXPECT_EQ(optionWords(band), (std::vector<std::string>{"--structure", "band", "--tension", "0.3", "--score-folds"}));
}

TEST(MakeOptions, ABadOptionIsRefusedInTheCommandLinesWords) {
  EXPECT_EQ(refusal([] {
              submittedOptions(json{"--structure", "band", "--samples", "999"});
            }),
            "--samples: Value 999 not in range 1 to 64");
  EXPECT_EQ(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"samples", 999}});
            }),
            "--samples: Value 999 not in range 1 to 64");
  EXPECT_EQ(refusal([] { submittedOptions(json{{"structure", "cube"}}); }), "--structure: cube not in {band,weave}");
  EXPECT_EQ(refusal([] { submittedOptions(json{{"panels", 30}}); }), "--structure is required");
  EXPECT_EQ(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"width", 0.5}});
            }),
            "--width is an option of the plain-woven structure (--structure weave), not of band");
  EXPECT_EQ(refusal([] {
              submittedOptions(json{{"structure", "weave"}, {"holes", "keep"}});
            }).substr(0, 12),
            "--holes keep");
  EXPECT_EQ(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"size", "2in"}, {"scale", 2}});
            }),
            "--scale excludes --size");
  EXPECT_EQ(refusal([] { submittedOptions(json{{"structure", "band"}, {"width", "2"}}); }).find("--width"), 0u);
  EXPECT_NE(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"out", "/tmp/x"}});
            }).find("--out is not a submission's option"),
            std::string::npos);
  EXPECT_NE(refusal([] {
              submittedOptions(json{"--structure", "band", "--bogus", "1"});
            }).find("--bogus"),
            std::string::npos);
  EXPECT_NE(refusal([] { submittedOptions(json{"--structure"}); }).find("--structure"), std::string::npos);
  EXPECT_NE(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"panels", "3.5"}});
            }).find("--panels"),
            std::string::npos);
  EXPECT_NE(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"score-folds", "yes"}});
            }).find("--score-folds"),
            std::string::npos);
  EXPECT_NE(refusal([] {
              submittedOptions(json{{"structure", "band"}, {"formats", "eps,pdf"}});
            }).find("pdf"),
            std::string::npos);
  EXPECT_EQ(refusal([] { submittedOptions(json(42)); }), "expected a list of words or an object of options");
}

TEST(MakeOptions, TheRequestTakesTheLengthsInTheirUnitsAndKeepsAGivenOrder) {
  const profiles::ProfileCatalogue catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  MakeOptions options = submittedOptions(json{{"structure", "band"}, {"size", "762mm"}, {"fastener", "3mm"}});
  MakeRequest request = requestOf(options, catalogue);
  EXPECT_NEAR(*request.size, 30.0, 1e-9);
  EXPECT_NEAR(*request.fastener, 3 / 25.4, 1e-9);
  EXPECT_EQ(request.order, OrderMode::Kits);
  options = submittedOptions(json{{"structure", "band"}, {"order", "window"}, {"kerf", "2furlongs"}});
  EXPECT_THROW(requestOf(options, catalogue), core::UserError);
  options.kerf.clear();
  EXPECT_EQ(requestOf(options, catalogue).order, OrderMode::Window);
}

}  // namespace
}  // namespace rotafab::jobs
