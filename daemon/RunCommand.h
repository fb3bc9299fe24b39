#pragma once
// `rotafab run DIR|SHEET --device URI` (SPEC, "Command line"; issue 5): drive
// a cutter directly, with a progress bar, Ctrl-C stopping it safely; and
// `rotafab devices` to list the cutters plugged in.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

// `argv`: the program's own, to run it again under umockdev for the simulated M2 Nano (sim:m2nano).
void addRunCommand(CLI::App& app, int& status, char** argv);

}  // namespace rotafab::cli
