// Usage errors as a new user meets them: a mistyped command, a command of the contract's
// that is not built yet (docs/CONTRACT.md, "Command line"), an option of the woven
// structure with band, and a bad option of a command, each one line with exit status 2
// and the `--help` to read.

#include <gtest/gtest.h>

#include "cli/CliSupport.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

void expectUsage(const std::string& args, const std::string& says, const std::string& help) {
  SCOPED_TRACE(args);
  const CommandResult r = run(kCli + " " + args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "error: " + says + "\nRun `" + help + "` for usage.\n");
}

TEST(UsageCli, EachUsageErrorSaysWhatIsWrongAndWhichHelpToRead) {
  const std::string cube = quoted(kSource / "examples/cube.obj");
  expectUsage("inpsect " + cube, "inpsect is not a rotafab command; did you mean `rotafab inspect`?", "rotafab --help");
  expectUsage("bake " + cube, "bake is not a rotafab command; did you mean `rotafab make`?", "rotafab --help");
  expectUsage("fabricate " + cube,
              "fabricate is not a rotafab command (the commands: inspect, make, manifest, nest, profiles, devices, "
              "run, submit, jobs, status, cancel, pause, resume, start, next, frame, move, dashboard)",
              "rotafab --help");
  expectUsage("",
              "give a command: inspect, make, manifest, nest, profiles, devices, run, submit, jobs, status, cancel, "
              "pause, resume, start, next, frame, move, dashboard",
              "rotafab --help");
  expectUsage("dashbord", "dashbord is not a rotafab command; did you mean `rotafab dashboard`?", "rotafab --help");
  // A mesh is planned by the daemon with `make`'s options, --structure first.
  expectUsage("submit " + cube, "--structure is required to plan a mesh (band or weave)", "rotafab submit --help");
  expectUsage("make " + cube + " --structure band --width 0.5",
              "--width is an option of the plain-woven structure (--structure weave), not of band",
              "rotafab make --help");
  // The parser's own errors point to the command's help, not the program's.
  // A mistyped option: the nearest the command has, before anything the parser says.
  expectUsage("make " + cube + " --panel 300", "--panel is not an option of make; did you mean --panels?",
              "rotafab make --help");
  expectUsage("make " + cube + " --sturcture band", "--sturcture is not an option of make; did you mean --structure?",
              "rotafab make --help");
  expectUsage("run x --devcie=sim:grbl", "--devcie is not an option of run; did you mean --device?",
              "rotafab run --help");
  expectUsage("status 3 --frobnicate", "--frobnicate is not an option of status (`rotafab status --help` lists them)",
              "rotafab status --help");
  const CommandResult noTarget = run(kCli + " run");
  EXPECT_EQ(noTarget.status, 2);
  EXPECT_NE(noTarget.err.find("TARGET is required\nRun `rotafab run --help` for usage.\n"), std::string::npos)
      << noTarget.err;
}

}  // namespace
// Each command's --help ends with examples of that command, not of another.
TEST(UsageCli, EachCommandsHelpShowsItsOwnExample) {
  for (const char* verb : {"inspect", "make", "manifest", "nest", "profiles", "devices", "run", "submit", "jobs",
                           "status", "cancel", "pause", "resume", "start", "next", "move", "dashboard"}) {
    SCOPED_TRACE(verb);
    const CommandResult help = run(kCli + " " + verb + " --help");
    EXPECT_EQ(help.status, 0) << help.err;
    const auto examples = help.out.rfind("Example");
    ASSERT_NE(examples, std::string::npos) << help.out;
    EXPECT_NE(help.out.find(std::string("rotafab ") + verb + " ", examples), std::string::npos) << help.out;
  }
}

}  // namespace rotafab::test
