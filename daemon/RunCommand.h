#pragma once
// `rotafab run DIR|SHEET --device URI` (SPEC, "Command line"; issue 5): drive
// a cutter directly, with a progress bar, Ctrl-C stopping it safely; and
// `rotafab devices` to list the cutters plugged in.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addRunCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
