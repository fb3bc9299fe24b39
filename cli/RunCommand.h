#pragma once
// `rotafab run DIR|SHEET --device URI` (docs/CONTRACT.md, "Command line"): drive a
// cutter directly, with a progress bar, Ctrl-C stopping it safely.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addRunCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
