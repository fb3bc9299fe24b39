// rotafab: the command line (docs/CONTRACT.md, "Command line"). Wiring only.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "cli/DevicesCommand.h"
#include "cli/ExitStatus.h"
#include "cli/InspectCommand.h"
#include "cli/MakeCommand.h"
#include "cli/ManifestCommand.h"
#include "cli/NestCommand.h"
#include "cli/ProfilesCommand.h"
#include "cli/QueueCommands.h"
#include "cli/RunCommand.h"
#include "core/HugePageHeap.h"

namespace {

size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The first option of `command` on the command line (after the command's
// name) that it does not have, said with the nearest it has: "--panel is
// not an option of make; did you mean --panels?". Empty when every option
// is one of its own. Said before the parser, which would otherwise answer
// "--structure is required" for "--sturcture band".
std::string mistypedOption(const CLI::App& command, int argc, char** argv) {
  std::vector<std::string> names;
  for (const CLI::Option* option : command.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
  }
  for (int i = 2; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word == "--") break;  // what follows is no option
    if (!word.starts_with("--") || word.size() == 2) continue;
    const std::string name(word.substr(0, word.find('=')));
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;
    std::string nearest;
    for (const std::string& candidate : names) {
      if (nearest.empty() || editDistance(name, candidate) < editDistance(name, nearest)) nearest = candidate;
    }
    const std::string verb = command.get_name();
    return !nearest.empty() && editDistance(name, nearest) <= 2
               ? fmt::format("{} is not an option of {}; did you mean {}?", name, verb, nearest)
               : fmt::format("{} is not an option of {} (`rotafab {} --help` lists them)", name, verb, verb);
  }
  return "";
}

// A usage error the parser would word as its own: one line, and where to read more.
int usageError(const std::string& message, const std::string& help) {
  fmt::print(stderr, "error: {}\nRun `{}` for usage.\n", message, help);
  return rotafab::core::kUsageError;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rotafab::cli;
  // Large jobs' first touches of their heap, in huge pages (core/HugePageHeap.h).
  rotafab::core::startAgainWithHugePageHeap(argv);
  CLI::App app{"rotafab: turn a 3D mesh into numbered laser-cut panels (Xing 2011), and run the cutter"};
  app.set_version_flag("--version", "rotafab 0.1.0");
  app.require_subcommand(1);
  int status = kSuccess;
  addInspectCommand(app, status);
  addMakeCommand(app, status);
  addManifestCommand(app, status);
  addNestCommand(app, status);
  addProfilesCommand(app, status);
  addDevicesCommand(app, status);
  addRunCommand(app, status);
  addQueueCommands(app, status);
  // (After the commands: a command made later would take this footer as its own.)
  app.footer(
      "Run `rotafab COMMAND --help` for a command's options and examples.\n\nExample:\n  rotafab inspect "
      "examples/bunny.obj");
  // The command named, if it is one: usage errors point to its own --help.
  std::vector<std::string> verbs;
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    verbs.push_back(command->get_name());
  }
  std::string verb;
  if (argc == 1) return usageError(fmt::format("give a command: {}", fmt::join(verbs, ", ")), "rotafab --help");
  if (argv[1][0] != '-') {
    const std::string_view word = argv[1];
    if (std::find(verbs.begin(), verbs.end(), word) != verbs.end()) {
      verb = word;
    } else {
      std::string nearest = verbs.front();
      for (const std::string& candidate : verbs) {
        if (editDistance(word, candidate) < editDistance(word, nearest)) nearest = candidate;
      }
      return usageError(
          editDistance(word, nearest) <= 2
              ? fmt::format("{} is not a rotafab command; did you mean `rotafab {}`?", word, nearest)
              : fmt::format("{} is not a rotafab command (the commands: {})", word, fmt::join(verbs, ", ")),
          "rotafab --help");
    }
  }
  if (!verb.empty()) {
    if (const std::string typo = mistypedOption(*app.get_subcommand(verb), argc, argv); !typo.empty()) {
      return usageError(typo, "rotafab " + verb + " --help");
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForAllHelp& help) {
    return app.exit(help);
  } catch (const CLI::CallForVersion& version) {
    return app.exit(version);
  } catch (const CLI::ParseError& error) {
    return usageError(error.what(), verb.empty() ? "rotafab --help" : "rotafab " + verb + " --help");
  } catch (const std::exception& error) {
    // Last resort (e.g. standard output closed): one line, never an abort.
    std::fprintf(stderr, "error: %s\n", error.what());
    return kUserError;
  }
  return status;
}
