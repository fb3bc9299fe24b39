#include "jobs/MakeOptions.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "core/UserError.h"
#include "profiles/Length.h"
#include "profiles/UserSettings.h"

namespace rotafab::jobs {
namespace {

using nlohmann::json;
using M = MakeOptions;

constexpr int kLeastWeaveSamples = 4;

using profiles::lengthOption;

std::string flag(std::string_view name) { return fmt::format("--{}", name); }

const MakeOption* optionNamed(std::string_view name) {
  const auto& table = makeOptionTable();
  const auto found =
      std::find_if(table.begin(), table.end(), [&](const MakeOption& option) { return option.name == name; });
  return found == table.end() ? nullptr : &*found;
}

// `text` as a T, the whole of it.
template <typename T>
std::optional<T> numberIn(const std::string& text) {
  T value{};
  const char* first = text.data();
  if (!text.empty() && text.front() == '+') ++first;
  const auto [end, error] = std::from_chars(first, text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) return std::nullopt;
  }
  return value;
}

// Sets the option's member from `text`, which whyNotAValue has passed.
void setFrom(const MakeOption& option, MakeOptions& options, const std::string& text) {
  std::visit(
      [&](auto member) {
        using Field = std::remove_cvref_t<decltype(options.*member)>;
        if constexpr (std::is_same_v<Field, std::string>) {
          options.*member = text;
        } else if constexpr (std::is_same_v<Field, bool>) {
          options.*member = true;
        } else if constexpr (std::is_same_v<Field, std::optional<double>> || std::is_same_v<Field, double>) {
          options.*member = *numberIn<double>(text);
        } else {
          options.*member = *numberIn<int>(text);
        }
      },
      option.member);
}

// The option's value as text (as a word of the command line).
std::string textOf(const MakeOption& option, const MakeOptions& options) {
  return std::visit(
      [&](auto member) -> std::string {
        using Field = std::remove_cvref_t<decltype(options.*member)>;
        const Field& value = options.*member;
        if constexpr (std::is_same_v<Field, std::string>) {
          return value;
        } else if constexpr (std::is_same_v<Field, bool>) {
          return value ? "true" : "";
        } else if constexpr (std::is_same_v<Field, std::optional<double>> ||
                             std::is_same_v<Field, std::optional<int>>) {
          return value ? fmt::format("{}", *value) : "";
        } else {
          return fmt::format("{}", value);
        }
      },
      option.member);
}

// The option's value as JSON: a number as a number, a flag as true, the rest as text.
json jsonOf(const MakeOption& option, const MakeOptions& options) {
  return std::visit(
      [&](auto member) -> json {
        using Field = std::remove_cvref_t<decltype(options.*member)>;
        const Field& value = options.*member;
        if constexpr (std::is_same_v<Field, std::optional<double>> || std::is_same_v<Field, std::optional<int>>) {
          return value ? json(*value) : json();
        } else {
          return json(value);
        }
      },
      option.member);
}

// A JSON value of an option given as text: a string as it is, a number as written.
std::string jsonText(const MakeOption& option, const json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_integer()) return value.dump();
  if (value.is_number_float()) return fmt::format("{}", value.get<double>());
  throw OptionError(fmt::format("{}: expected {}", flag(option.name),
                                option.value == OptionValue::Flag ? "true or false" : "text or a number"));
}

// The options of a list of `make`'s words, as the JSON object they stand for.
json objectOfWords(const json& words) {
  json object = json::object();
  for (size_t at = 0; at < words.size(); ++at) {
    if (!words[at].is_string()) throw OptionError("expected a list of words such as [\"--structure\", \"band\"]");
    std::string word = words[at].get<std::string>();
    std::optional<std::string> value;
    if (const size_t equals = word.find('='); word.starts_with("--") && equals != std::string::npos) {
      value = word.substr(equals + 1);
      word.resize(equals);
    }
    const MakeOption* option = word.starts_with("--") ? optionNamed(std::string_view(word).substr(2)) : nullptr;
    if (!option) {
      throw OptionError(word.starts_with("-") ? fmt::format("The following argument was not expected: {}", word)
                                              : fmt::format("{}: the mesh is the submission's file, not a word of "
                                                            "its options",
                                                            word));
    }
    if (object.contains(option->name)) throw OptionError(fmt::format("{}: given twice", word));
    if (option->value == OptionValue::Flag) {
      if (value) throw OptionError(fmt::format("{}: takes no value", word));
      object[std::string(option->name)] = true;
      continue;
    }
    if (!value) {
      if (at + 1 >= words.size() || !words[at + 1].is_string()) throw OptionError(fmt::format("{}: 1 required", word));
      value = words[++at].get<std::string>();
    }
    object[std::string(option->name)] = *value;
  }
  return object;
}

}  // namespace

const std::vector<MakeOption>& makeOptionTable() {
  using V = OptionValue;
  static const std::vector<MakeOption> table{
      MakeOption("structure", V::Choice, "band (dissertation ch. V) or weave (ch. IV)", &M::structure)
          .among({"band", "weave"}),
      MakeOption("out", V::Text, "Output folder (default: MESHNAME-STRUCTURE, e.g. bunny-band)", &M::out).daemonsOwn(),
      MakeOption("machine", V::Text, "Machine profile: the bed, margins and colours", &M::machine).shown(),
      MakeOption("material", V::Text, "Material profile: kerf and fastener diameter", &M::material).shown(),
      MakeOption("json", V::Flag, "Print one JSON object: panels, sheets, fasteners, utilization, seconds per phase",
                 &M::json)
          .daemonsOwn(),
      MakeOption("size", V::Length, "Scale so that the largest bounding-box side is this long", &M::size),
      MakeOption("scale", V::Number, "Scale the mesh by this factor (inches per mesh unit)", &M::scale).notWith("size"),
      MakeOption("holes", V::Choice,
                 "Open meshes: keep the boundary open (the default for band), fill each hole with one face (the "
                 "default for weave), patch it with triangles as long as its edges (for a wide or bent hole, "
                 "whose one face would make a weave's panels as wide as the hole), or error: refuse",
                 &M::holes)
          .among({"keep", "fill", "patch", "error"}),
      MakeOption("repair", V::Choice,
                 "auto: weld, drop duplicate faces, split non-manifold edges and bow-tie vertices, orient (each "
                 "repair said and recorded in manifest.json); none: refuse a broken mesh",
                 &M::repair)
          .among({"auto", "none"})
          .shown(),
      MakeOption("merge-coplanar", V::Number,
                 "Merge adjacent faces within this many degrees of one plane into one panel (default: 1 for STL, "
                 "whose faces are all triangles; 0 for other formats)",
                 &M::mergeCoplanar)
          .within(0.0, 45.0),
      MakeOption("panels", V::Whole,
                 "Remesh to even triangles that give about this many panels (N faces for band, about 2N/3 for\n"
                 "weave, a panel an edge), keeping the shape, the genus, the boundary and sharp creases",
                 &M::panels)
          .within(4, 10000000),
      MakeOption("tension", V::Number,
                 "Corner-cutting tension a of eq. 5.2, 0 < a < 1 (default: Doo-Sabin, a = 1/4 + 5/(4N))", &M::tension)
          .only(OptionFor::Band),
      MakeOption("samples", V::Whole,
                 "Segments along each edge band (band), or along each ribbon's Bézier curve between crossings "
                 "(weave)",
                 &M::samples)
          .within(1, 64)
          .shown(),
      MakeOption("width", V::Fraction,
                 "Weave: the ribbons' share of their edge region across them, 0 < W <= 1 (eq. 4.6-4.9; default\n"
                 "0.8, narrowed edge by edge where ribbons would pass through each other; a W given is kept)",
                 &M::width)
          .only(OptionFor::Weave),
      MakeOption("curve", V::Fraction,
                 "Weave: each crossing's share of its edge region along the ribbon, 0 < C <= 1 (default 0.6;\n"
                 "smaller curves the ribbons more between crossings; eq. 4.2-4.5)",
                 &M::curve)
          .only(OptionFor::Weave),
      MakeOption("offset", V::Length,
                 "Weave: how far a ribbon stands over (or under) the surface at a crossing (default: half the\n"
                 "material's thickness, at least 0.01in)",
                 &M::offset)
          .only(OptionFor::Weave),
      MakeOption("cycles", V::Choice,
                 "Weave: all (every edge crossed: a thread per Petrie walk) or single (one thread weaves the\n"
                 "whole object, crossing the edges of a spanning tree of the dual)",
                 &M::cycles)
          .among({"all", "single"})
          .only(OptionFor::Weave)
          .shown(),
      MakeOption("fastener", V::Length, "Fastener hole diameter (default: the material's, 1/8 in)", &M::fastener),
      MakeOption("kerf", V::Length, "Kerf (default: the material's)", &M::kerf),
      MakeOption("start", V::Whole, "Flood-fill start face (index in the file; default: the lowest face)", &M::start)
          .only(OptionFor::Band),
      MakeOption("up", V::Choice, "The vertical axis, for the lowest face", &M::up).among({"x", "y", "z"}).shown(),
      MakeOption("score-folds", V::Flag, "Score the folds between each vertex band and its bands", &M::scoreFolds)
          .only(OptionFor::Band),
      MakeOption("keep-faces", V::Flag,
                 "Keep every face as drawn: a band (or a weave's crossing) with no room for its fastener stops the\n"
                 "job, rather than its short edge or the sliver beside it being collapsed (a repair, listed in\n"
                 "manifest.json)",
                 &M::keepFaces),
      MakeOption("glue-narrow", V::Flag,
                 "Glue the bands (or a weave's crossings) that have no room for a fastener even after mending,\n"
                 "rather than stop the job (manifest.txt lists them)",
                 &M::glueNarrow),
      MakeOption("time", V::Number,
                 "Nesting time budget in seconds, first layout included: the best layout found\n"
                 "by then is kept; parts the first layout has not reached by then go in rows (with a note)",
                 &M::seconds)
          .within(0.0, 86400.0)
          .shown(),
      MakeOption("evaluations", V::Whole,
                 "Stop the nesting's searches after this many layouts each, the first included: with a --time\n"
                 "long enough, the same sheets on every machine of as many cores (1: the first layout only)",
                 &M::evaluations)
          .within(0, 1000000000),
      MakeOption("order", V::Choice,
                 "Cutting order: kits (each sheet a run of the assembly steps, nested freely within it; the\n"
                 "default), strict, window or free (the fewest sheets, the steps anywhere; see `rotafab nest`)",
                 &M::order)
          .among({"kits", "strict", "window", "free"})
          .shown(),
      MakeOption("window", V::Whole, "With --order window: at most this many places from the assembly order",
                 &M::window)
          .shown(),
      MakeOption("layout", V::Choice,
                 "nest (true shapes, interlocking) or rows (boxes in rows, in assembly order, on more sheets: a "
                 "quick preview; --order, --window and --time do not apply)",
                 &M::layout)
          .among({"nest", "rows"})
          .shown(),
      MakeOption("units", V::Choice,
                 "Show lengths in mm or in: the summary, manifest.txt, the previews, run and the page (default:\n"
                 "`units:` in ~/.config/rotafab/config.yaml, else --size's unit, else the bed's); files stay in inches",
                 &M::units)
          .among({"mm", "in"}),
      MakeOption("formats", V::Formats,
                 "Sheet files to write, of eps, svg and dxf, e.g. eps,svg,dxf (default: eps,svg, and dxf where the\n"
                 "machine profile's `formats` names it); `rotafab run` and the daemon cut from the SVG",
                 &M::formats),
  };
  return table;
}

std::string whyNotAValue(const MakeOption& option, const std::string& text) {
  const bool ranged = option.least != option.most;
  switch (option.value) {
    case OptionValue::Text:
    case OptionValue::Length:  // (checked as the request is made, naming the unit)
    case OptionValue::Flag:
      return {};
    case OptionValue::Choice: {
      if (std::find(option.choices.begin(), option.choices.end(), text) != option.choices.end()) return {};
      std::string set;
      for (std::string_view choice : option.choices) set += fmt::format("{}{}", set.empty() ? "" : ",", choice);
      return fmt::format("{} not in {{{}}}", text, set);
    }
    case OptionValue::Fraction: {
      char* end = nullptr;
      const double number = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') {
        return fmt::format(
            "{}: expected a plain number more than 0 and at most 1 (a share of the edge's region, no unit)", text);
      }
      if (!(number > 0 && number <= 1)) return fmt::format("{}: expected more than 0 and at most 1", text);
      return {};
    }
    case OptionValue::Number: {
      const auto number = numberIn<double>(text);
      if (!number) return fmt::format("{}: expected a number", text);
      if (ranged && (*number < option.least || *number > option.most)) {
        return fmt::format("Value {} not in range {} to {}", text, std::to_string(option.least),
                           std::to_string(option.most));
      }
      return {};
    }
    case OptionValue::Whole: {
      const auto number = numberIn<int>(text);
      if (!number) return fmt::format("{}: expected a whole number", text);
      if (ranged && (*number < option.least || *number > option.most)) {
        return fmt::format("Value {} not in range {} to {}", text, static_cast<long long>(option.least),
                           static_cast<long long>(option.most));
      }
      return {};
    }
    case OptionValue::Formats:
      try {
        formatsOf(text);
        return {};
      } catch (const std::invalid_argument& error) {
        return error.what();
      }
  }
  return {};
}

void checkStructureOptions(const MakeOptions& options) {
  const bool weave = options.structure == "weave";
  for (const MakeOption& option : makeOptionTable()) {
    if (!options.given.contains(std::string(option.name))) continue;
    if (weave && option.structure == OptionFor::Band) {
      throw OptionError(
          fmt::format("{} is an option of the band decomposition (--structure band), not of weave", flag(option.name)));
    }
    if (!weave && option.structure == OptionFor::Weave) {
      throw OptionError(fmt::format("{} is an option of the plain-woven structure (--structure weave), not of band",
                                    flag(option.name)));
    }
  }
  if (weave && options.samples < kLeastWeaveSamples) {
    throw OptionError(fmt::format(
        "--samples {}: a weave needs at least {} (its panels run half a Bézier segment past each crossing under, to "
        "hold its holes)",
        options.samples, kLeastWeaveSamples));
  }
  if (weave && options.holes == "keep") {
    throw OptionError(
        "--holes keep: a plain weave crosses every edge, and a boundary edge has one side; fill (the default for "
        "weave) caps each hole with a face, patch closes it with triangles like the mesh's own, error refuses an "
        "open mesh");
  }
}

MakeOptions submittedOptions(const json& given) {
  const json object = given.is_null() ? json::object() : given.is_array() ? objectOfWords(given) : given;
  if (!object.is_object()) throw OptionError("expected a list of words or an object of options");
  MakeOptions options;
  for (const auto& [key, value] : object.items()) {
    const MakeOption* option = optionNamed(key.starts_with("--") ? std::string_view(key).substr(2) : key);
    if (!option) throw OptionError(fmt::format("The following argument was not expected: {}", flag(key)));
    if (!option->submittable) {
      throw OptionError(
          fmt::format("{} is not a submission's option: the daemon keeps the job's files and `rotafab "
                      "status --json` gives its summary",
                      flag(option->name)));
    }
    if (option->value == OptionValue::Flag) {
      if (!value.is_boolean()) throw OptionError(fmt::format("{}: expected true or false", flag(option->name)));
      if (!value.get<bool>()) continue;
      setFrom(*option, options, "true");
    } else {
      const std::string text = jsonText(*option, value);
      if (const std::string why = whyNotAValue(*option, text); !why.empty()) {
        throw OptionError(fmt::format("{}: {}", flag(option->name), why));
      }
      setFrom(*option, options, text);
    }
    options.given.insert(std::string(option->name));
  }
  for (const MakeOption& option : makeOptionTable()) {
    if (!option.excludes.empty() && options.given.contains(std::string(option.name)) &&
        options.given.contains(std::string(option.excludes))) {
      throw OptionError(fmt::format("{} excludes {}", flag(option.name), flag(option.excludes)));
    }
  }
  if (!options.given.contains("structure")) throw OptionError("--structure is required");
  checkStructureOptions(options);
  return options;
}

json optionsJson(const MakeOptions& options) {
  json object = json::object();
  for (const MakeOption& option : makeOptionTable()) {
    if (options.given.contains(std::string(option.name))) object[std::string(option.name)] = jsonOf(option, options);
  }
  return object;
}

std::vector<std::string> optionWords(const MakeOptions& options) {
  std::vector<std::string> words;
  for (const MakeOption& option : makeOptionTable()) {
    if (!options.given.contains(std::string(option.name))) continue;
    words.push_back(flag(option.name));
    if (option.value != OptionValue::Flag) words.push_back(textOf(option, options));
  }
  return words;
}

std::string flagOf(geometry::Parameter parameter) {
  switch (parameter) {
    case geometry::Parameter::Structure:
      return "--structure";
    case geometry::Parameter::Holes:
      return "--holes";
    case geometry::Parameter::Repair:
      return "--repair";
    case geometry::Parameter::MergeCoplanar:
      return "--merge-coplanar";
    case geometry::Parameter::Panels:
      return "--panels";
    case geometry::Parameter::Size:
      return "--size";
    case geometry::Parameter::Scale:
      return "--scale";
    case geometry::Parameter::Fastener:
      return "--fastener";
    case geometry::Parameter::Start:
      return "--start";
    case geometry::Parameter::Width:
      return "--width";
    case geometry::Parameter::Offset:
      return "--offset";
    case geometry::Parameter::KeepFaces:
      return "--keep-faces";
    case geometry::Parameter::GlueNarrow:
      return "--glue-narrow";
  }
  return "--" + geometry::parameterInWords(parameter);
}

OrderMode orderModeOf(const std::string& order) {
  return order == "strict"   ? OrderMode::Strict
         : order == "free"   ? OrderMode::Free
         : order == "window" ? OrderMode::Window
                             : OrderMode::Kits;
}

MakeRequest requestOf(const MakeOptions& options, const profiles::ProfileCatalogue& catalogue) {
  MakeRequest request;
  request.mesh = options.mesh;
  request.structure = options.structure == "weave" ? geometry::StructureKind::Weave : geometry::StructureKind::Band;
  request.machine = profiles::findMachine(catalogue, options.machine);
  request.material = profiles::findMaterial(catalogue, options.material);
  if (!options.size.empty()) request.size = lengthOption(options.size, "--size", true);
  request.scale = options.scale;
  // docs/CONTRACT.md, "Layout": fill by default for weave (every edge is crossed), keep for band.
  const std::string holes = !options.holes.empty()                                ? options.holes
                            : request.structure == geometry::StructureKind::Weave ? "fill"
                                                                                  : "keep";
  request.holes = holes == "fill"    ? HolesMode::Fill
                  : holes == "patch" ? HolesMode::Patch
                  : holes == "error" ? HolesMode::Error
                                     : HolesMode::Keep;
  request.repair = options.repair == "auto";
  request.mergeCoplanar = options.mergeCoplanar;
  request.panels = options.panels;
  request.tension = options.tension;
  request.samples = options.samples;
  if (!options.fastener.empty()) request.fastener = lengthOption(options.fastener, "--fastener", true);
  request.start = options.start;
  request.up = options.up == "x" ? 0 : options.up == "y" ? 1 : 2;
  request.scoreFolds = options.scoreFolds;
  request.keepFaces = options.keepFaces;
  request.glueNarrow = options.glueNarrow;
  request.width = options.width;
  if (options.curve) request.curve = *options.curve;
  if (!options.offset.empty()) request.offset = lengthOption(options.offset, "--offset", true);
  request.cycles = options.cycles == "single" ? geometry::WeaveCycles::Single : geometry::WeaveCycles::All;
  if (!options.kerf.empty()) request.kerf = lengthOption(options.kerf, "--kerf");
  request.seconds = options.seconds;
  request.evaluations = options.evaluations;
  request.order = orderModeOf(options.order);
  request.window = options.window;
  request.rows = options.layout == "rows";
  if (!options.formats.empty()) request.formats = formatsOf(options.formats);  // checked by whyNotAValue
  request.names = flagOf;
  request.shownIn = profiles::shownUnit(options.units, std::nullopt, options.size, request.machine.bed.unit);
  return request;
}

}  // namespace rotafab::jobs
