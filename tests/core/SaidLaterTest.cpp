// What a try says, kept until it is kept (core/WorkContext.h, SaidLater):
// nothing reaches the caller's log before sayOn(), then every note and
// warning, from any thread, with its level; the progress is the caller's,
// or none.

#include <gtest/gtest.h>
#include <spdlog/logger.h>
#include <spdlog/sinks/ostream_sink.h>

#include <sstream>
#include <string>

#include "core/WorkContext.h"

namespace rotafab::core {
namespace {

TEST(SaidLater, KeepsNotesAndWarningsUntilSaidThenSaysEachWithItsLevel) {
  std::ostringstream out;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out);
  sink->set_pattern("%l %v");
  auto log = std::make_shared<spdlog::logger>("caller", sink);
  Executor executor(2);
  Cancellation cancellation;
  int reported = 0;
  const WorkContext caller(
      executor, cancellation, [&](const Progress&) { ++reported; }, log);

  const SaidLater said;
  const WorkContext trying = said.context(caller);
  trying.note("remeshed");
  trying.warn("1 label is not etched");
  trying.parallelFor(50, [&](size_t i) { trying.note("band " + std::to_string(i)); });
  trying.report({"geometry", "", 0, 0});
  EXPECT_EQ(out.str(), "") << "said before it was kept";
  EXPECT_EQ(reported, 1) << "the caller's progress";
  said.context(caller, false).report({"geometry", "", 0, 0});
  EXPECT_EQ(reported, 1) << "no progress asked";

  said.sayOn(caller);
  const std::string lines = out.str();
  EXPECT_EQ(lines.rfind("info remeshed\nwarning 1 label is not etched\n", 0), 0u) << lines;
  for (int i = 0; i < 50; ++i) {
    EXPECT_NE(lines.find("info band " + std::to_string(i) + "\n"), std::string::npos) << i;
  }
}

}  // namespace
}  // namespace rotafab::core
