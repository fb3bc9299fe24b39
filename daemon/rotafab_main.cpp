// rotafab: the command line (SPEC, "Command line"). Wiring only.

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>

#include "daemon/DevicesCommand.h"
#include "daemon/ExitCode.h"
#include "daemon/InspectCommand.h"
#include "daemon/MakeCommand.h"
#include "daemon/ManifestCommand.h"
#include "daemon/NestCommand.h"
#include "daemon/ProfilesCommand.h"
#include "daemon/RunCommand.h"

int main(int argc, char** argv) {
  using namespace rotafab::cli;
  CLI::App app{"rotafab: turn a 3D mesh into numbered laser-cut panels (Xing 2011), and run the cutter"};
  app.set_version_flag("--version", "rotafab 0.1.0");
  app.require_subcommand(1);
  app.footer(
      "Run `rotafab COMMAND --help` for a command's options and examples.\n\nExample:\n  rotafab inspect "
      "examples/bunny.obj");
  int status = kSuccess;
  addInspectCommand(app, status);
  addMakeCommand(app, status);
  addManifestCommand(app, status);
  addNestCommand(app, status);
  addProfilesCommand(app, status);
  addDevicesCommand(app, status);
  addRunCommand(app, status);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForVersion& version) {
    return app.exit(version);
  } catch (const CLI::ParseError& error) {
    fmt::print(stderr, "error: {}\nRun `rotafab --help` for usage.\n", error.what());
    return kUsageError;
  } catch (const std::exception& error) {
    // Last resort (e.g. standard output closed): one line, never an abort.
    std::fprintf(stderr, "error: %s\n", error.what());
    return kUserError;
  }
  return status;
}
