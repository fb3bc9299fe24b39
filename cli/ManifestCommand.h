#pragma once
// `rotafab manifest DIR [--format text|json|html]` (docs/CONTRACT.md, "Command line"):
// the assembly manifest of a `make` output folder, again.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addManifestCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
