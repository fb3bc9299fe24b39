#pragma once
// The options of `rotafab make` (and `rotafab submit`) on the command line:
// declared from the one table of jobs/MakeOptions.h, parsed by CLI11.

#include <CLI/CLI.hpp>

#include "jobs/MakeOptions.h"

namespace rotafab::cli {

using jobs::MakeOptions;

// Declares the mesh and every option of `make` on the verb, into `options`.
void addMakeOptions(CLI::App& make, MakeOptions& options);

// Once parsed: notes the options given in `options.given`, then checks them
// against the structure chosen (jobs::checkStructureOptions); throws
// CLI::ValidationError naming the option (a usage error).
void checkStructureOptions(const CLI::App& make, MakeOptions& options);

}  // namespace rotafab::cli
