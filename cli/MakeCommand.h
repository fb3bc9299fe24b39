#pragma once
// `rotafab make MESH --structure band` (docs/CONTRACT.md, "Command line"): from a
// mesh to laser sheets, an assembly manifest and the 3D structure; and
// `rotafab manifest DIR` to print that manifest again.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addMakeCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
