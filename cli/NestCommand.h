#pragma once
// `rotafab nest INSTANCE.json` (docs/CONTRACT.md, "nest"): nest the parts of a jagua-rs /
// sparrow instance file onto beds or into a strip.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addNestCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
