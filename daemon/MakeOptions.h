#pragma once
// The options of `rotafab make` (SPEC, "Command line"): their table, and the
// request (jobs/MakeJob.h) they make.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "jobs/MakeJob.h"
#include "jobs/Nesting.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {

struct MakeOptions {
  std::string mesh, structure, out, machine = "workshop-32x18", material = "posterboard";
  std::string size, fastener, kerf, holes, repair = "auto", up = "y", order = "window", layout = "nest";
  std::string offset, cycles = "all";  // the weave's
  std::optional<double> width, curve;  // the weave's: fractions, no unit
  std::string formats;                 // empty: the machine profile's (jobs::defaultFormats())
  bool orderGiven = false;             // --order given: kept even where the free order would save a sheet
  std::optional<double> scale, tension, mergeCoplanar;
  std::optional<int> start, panels;
  int samples = 8, window = 8, evaluations = 0;
  double seconds = jobs::kDefaultNestingSeconds;
  bool json = false, scoreFolds = false;
};

// Declares every option of `make` on the verb, into `options`.
void addMakeOptions(CLI::App& make, MakeOptions& options);

// Options given that the structure chosen does not take (--width with band,
// --tension with weave, ...), and --holes keep with weave: throws
// CLI::ValidationError naming the option.
void checkStructureOptions(const CLI::App& make, const MakeOptions& options);

// The request the options make; throws core::UserError on a bad length or an
// unknown profile.
jobs::MakeRequest requestOf(const MakeOptions& options, const profiles::ProfileCatalogue& catalogue);

}  // namespace rotafab::cli
