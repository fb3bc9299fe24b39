#pragma once
// `rotafab inspect MESH [--json]` (docs/CONTRACT.md, "Command line").

#include <CLI/CLI.hpp>

namespace rotafab::cli {

// Registers the subcommand; the callback stores its exit status in `status`.
void addInspectCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
