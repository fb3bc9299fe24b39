#pragma once
// `rotafab profiles [--json] [FILE...]`: list the machine and material profiles
// on the search path, or check the given profile files.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addProfilesCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
