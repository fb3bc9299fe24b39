#pragma once
// `rotafab devices [--json]` (docs/CONTRACT.md, "Command line"): the serial ports and
// cutters plugged in, and the driver and URI for each.

#include <CLI/CLI.hpp>

namespace rotafab::cli {

void addDevicesCommand(CLI::App& app, int& status);

}  // namespace rotafab::cli
