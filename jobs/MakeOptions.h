#pragma once
// The options of `make` (docs/CONTRACT.md, "Command line"), typed, in one
// table that both programs read: the command line declares its options from
// it and parses them from words (cli/MakeOptionsCli.h); the daemon reads a
// submission's options from the API's JSON with it, keeps them as JSON and
// makes the job's request from them, never through words.

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "geometry/Parameters.h"
#include "jobs/MakeJob.h"
#include "jobs/Nesting.h"
#include "profiles/Profiles.h"

namespace rotafab::jobs {

struct MakeOptions {
  std::string mesh, structure, out, machine = "workshop-32x18", material = "posterboard";
  std::string size, fastener, kerf, holes, repair = "auto", up = "y", order = "kits", layout = "nest";
  std::string offset, cycles = "all";  // the weave's
  std::string units;                   // mm or in; empty: the caller's setting, else --size's unit
  std::optional<double> width, curve;  // the weave's: fractions, no unit
  std::string formats;                 // empty: the machine profile's (jobs::defaultFormats())
  std::optional<double> scale, tension, mergeCoplanar;
  std::optional<int> start, panels;
  int samples = 8, window = 8, evaluations = 0;
  double seconds = kDefaultNestingSeconds;
  bool json = false, scoreFolds = false, keepFaces = false, glueNarrow = false;
  // The options given, by name ("machine"): a --machine given must be the
  // device's.
  std::set<std::string> given;
};

// What an option's value is, and how it is checked.
enum class OptionValue {
  Text,      // free text (a profile's name, an output folder)
  Choice,    // one of `choices`
  Length,    // a length in in, mm or cm, checked when the request is made
  Fraction,  // a plain number more than 0 and at most 1
  Number,    // a number, in [least, most] when they differ
  Whole,     // a whole number, in [least, most] when they differ
  Formats,   // a list of eps, svg and dxf
  Flag,      // given or not
};

// Which structure an option belongs to.
enum class OptionFor { Both, Band, Weave };

struct MakeOption {
  using Member =
      std::variant<std::string MakeOptions::*, std::optional<double> MakeOptions::*, std::optional<int> MakeOptions::*,
                   int MakeOptions::*, double MakeOptions::*, bool MakeOptions::*>;
  MakeOption(std::string_view name, OptionValue value, std::string_view help, Member member)
      : name(name), value(value), help(help), member(member) {}

  std::string_view name;  // "merge-coplanar": --merge-coplanar, and its key in a submission's JSON
  OptionValue value;
  std::string_view help;
  Member member;
  std::vector<std::string_view> choices;
  double least = 0, most = 0;
  OptionFor structure = OptionFor::Both;
  bool showDefault = false;   // its default said in the help
  bool submittable = true;    // false: the daemon's to choose (the output folder, the summary's form)
  std::string_view excludes;  // an option that may not be given with it

  // The table's entries are written as MakeOption(...).among({...}).within(1, 64).shown().
  MakeOption among(std::vector<std::string_view> words) const {
    MakeOption option = *this;
    option.choices = std::move(words);
    return option;
  }
  MakeOption within(double low, double high) const {
    MakeOption option = *this;
    option.least = low, option.most = high;
    return option;
  }
  MakeOption only(OptionFor kind) const {
    MakeOption option = *this;
    option.structure = kind;
    return option;
  }
  MakeOption shown() const {
    MakeOption option = *this;
    option.showDefault = true;
    return option;
  }
  MakeOption daemonsOwn() const {
    MakeOption option = *this;
    option.submittable = false;
    return option;
  }
  MakeOption notWith(std::string_view other) const {
    MakeOption option = *this;
    option.excludes = other;
    return option;
  }
};

// Every option of `make` but the mesh, in the order `rotafab make --help` lists them.
const std::vector<MakeOption>& makeOptionTable();

// A bad option or option value, in the command line's words
// ("--samples: Value 999 not in range 1 to 64"): a usage error.
class OptionError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Why `text` is not a value of `option` (empty: it is), as the command line says it.
std::string whyNotAValue(const MakeOption& option, const std::string& text);

// Options given that the structure chosen does not take (--width with band,
// --tension with weave, ...), too few samples for a weave, and --holes keep
// with weave: throws OptionError naming the option.
void checkStructureOptions(const MakeOptions& options);

// The options a submission carries, from the API's JSON: an object of
// options by name ({"structure": "band", "panels": 300, "score-folds":
// true}), or a list of `make`'s words (["--structure", "band"]), the form
// jobs were kept in before. Checked as the command line checks them (and
// --structure required); --out and --json refused. Throws OptionError.
MakeOptions submittedOptions(const nlohmann::json& options);

// The options given, as the JSON object `submittedOptions` reads.
nlohmann::json optionsJson(const MakeOptions& options);

// The options given, as `rotafab make`'s words (a job's "options" in the API).
std::vector<std::string> optionWords(const MakeOptions& options);

// An option's flag, for messages: "--fastener".
std::string flagOf(geometry::Parameter parameter);

// --order kits|strict|window|free (anything else: kits).
OrderMode orderModeOf(const std::string& order);

// The request the options make; throws core::UserError on a bad length or an
// unknown profile.
MakeRequest requestOf(const MakeOptions& options, const profiles::ProfileCatalogue& catalogue);

}  // namespace rotafab::jobs
