#include "daemon/NestCommand.h"

#include <fmt/format.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "daemon/ExitCode.h"
#include "jobs/AtomicFile.h"
#include "jobs/Nesting.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {
namespace {

struct NestOptions {
  std::string instance;
  std::string bed;
  std::string margin;
  std::string spacing;
  std::string machine = "workshop-32x18";
  bool strip = false;
  double seconds = 5.0;
  std::string out;
  bool json = false;
  std::string order = "free";
  int window = 8;
  unsigned seed = 1;
};

class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

double lengthOption(const std::string& text, const char* option) {
  const auto value = profiles::parseLength(text);
  if (!value || *value < 0) {
    throw UserError(fmt::format("{} {}: expected a length such as 0.25in, 6.35mm or 0.635cm", option, text));
  }
  return *value;
}

struct Item {
  int id = 0;
  int demand = 1;
};

// Reads the instance: one part per copy of each item. Names the element at fault.
std::vector<jobs::NestingPart> readInstance(const std::string& file, std::vector<Item>& items, double& stripHeight) {
  std::ifstream in(file);
  if (!in) throw UserError(fmt::format("{}: cannot open the file", file));
  nlohmann::json instance;
  try {
    instance = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& error) {
    throw UserError(fmt::format("{}: not JSON: {}", file, error.what()));
  }
  auto fail = [&](const std::string& where, const std::string& what) -> UserError {
    return UserError(fmt::format("{}: {}: {}", file, where, what));
  };
  if (!instance.is_object() || !instance.contains("items") || !instance["items"].is_array()) {
    throw fail("items", "expected an object with an \"items\" list");
  }
  stripHeight = instance.value("strip_height", 0.0);
  std::vector<jobs::NestingPart> parts;
  for (size_t i = 0; i < instance["items"].size(); ++i) {
    const auto& item = instance["items"][i];
    const std::string at = fmt::format("items[{}]", i);
    if (!item.is_object()) throw fail(at, "expected an object");
    Item entry;
    entry.id = item.contains("id") && item["id"].is_number_integer() ? item["id"].get<int>() : static_cast<int>(i);
    if (item.contains("demand")) {
      if (!item["demand"].is_number_integer() || item["demand"].get<int>() < 1 || item["demand"].get<int>() > 100000) {
        throw fail(at + ".demand", "expected a whole number from 1");
      }
      entry.demand = item["demand"].get<int>();
    }
    std::vector<double> rotations{0.0};
    if (item.contains("allowed_orientations")) {
      rotations.clear();
      for (const auto& r : item["allowed_orientations"]) {
        if (!r.is_number()) throw fail(at + ".allowed_orientations", "expected numbers (degrees)");
        rotations.push_back(r.get<double>());
      }
      if (rotations.empty()) throw fail(at + ".allowed_orientations", "is empty");
    }
    const auto shape = item.value("shape", nlohmann::json::object());
    if (shape.value("type", "") != "simple_polygon") throw fail(at + ".shape.type", "only simple_polygon is supported");
    if (!shape.contains("data") || !shape["data"].is_array())
      throw fail(at + ".shape.data", "expected a list of points");
    jobs::Polygon2 outline;
    for (size_t k = 0; k < shape["data"].size(); ++k) {
      const auto& point = shape["data"][k];
      if (!point.is_array() || point.size() != 2 || !point[0].is_number() || !point[1].is_number()) {
        throw fail(fmt::format("{}.shape.data[{}]", at, k), "expected [x, y]");
      }
      outline.emplace_back(point[0].get<double>(), point[1].get<double>());
      if (!outline.back().allFinite()) throw fail(fmt::format("{}.shape.data[{}]", at, k), "not a finite point");
    }
    if (outline.size() > 1 && outline.front() == outline.back()) outline.pop_back();  // closed rings repeat the start
    if (outline.size() < 3 || std::abs(jobs::polygonArea(outline)) <= 0) {
      throw fail(at + ".shape.data", "expected a polygon of at least 3 points with area");
    }
    for (int copy = 0; copy < entry.demand; ++copy) {
      jobs::NestingPart part;
      part.name = fmt::format("item {} copy {}", entry.id, copy + 1);
      part.outline = outline;
      part.rotations = rotations;
      part.order = static_cast<int>(parts.size());
      parts.push_back(std::move(part));
    }
    items.push_back(entry);
  }
  if (parts.empty()) throw fail("items", "no items");
  return parts;
}

std::string layoutSvg(const std::vector<jobs::NestingPart>& parts, const jobs::NestingResult& result,
                      const jobs::NestingOptions& options, double margin) {
  const double width = options.strip ? std::max(result.stripLength, 1e-9) : options.width + 2 * margin;
  const double height = options.strip ? options.height : options.height + 2 * margin;
  const double gap = height * 0.05;
  const int sheets = std::max(1, result.sheets);
  const double total = sheets * height + (sheets - 1) * gap;
  std::ostringstream svg;
  svg << fmt::format(
      R"(<?xml version="1.0" encoding="UTF-8"?>)"
      "\n"
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="{:.4f}in" height="{:.4f}in" viewBox="0 0 {:.4f} {:.4f}">)"
      "\n",
      width, total, width, total);
  for (int s = 0; s < sheets; ++s) {
    const double top = s * (height + gap);
    svg << fmt::format(
        R"(<rect x="0" y="{:.4f}" width="{:.4f}" height="{:.4f}" fill="#f4f4f4" stroke="#000" stroke-width="{:.4f}"/>)"
        "\n",
        top, width, height, height * 0.002);
  }
  for (const auto& placement : result.placements) {
    const double top = (placement.sheet - 1) * (height + gap);
    std::string d;
    for (const auto& p : jobs::placedOutline(parts[placement.part], placement)) {
      d += fmt::format("{}{:.4f},{:.4f} ", d.empty() ? "M" : "L", p.x() + margin, top + height - (p.y() + margin));
    }
    svg << fmt::format(R"(<path d="{}Z" fill="#8ab4f8" stroke="#1a4f9c" stroke-width="{:.4f}"><title>{}</title></path>)"
                       "\n",
                       d, height * 0.001, parts[placement.part].name);
  }
  svg << "</svg>\n";
  return svg.str();
}

int runNest(const NestOptions& options) {
  try {
    const auto start = std::chrono::steady_clock::now();
    std::vector<Item> items;
    double stripHeight = 0;
    std::vector<jobs::NestingPart> parts = readInstance(options.instance, items, stripHeight);

    jobs::NestingOptions nesting;
    nesting.strip = options.strip;
    nesting.seconds = options.seconds;
    nesting.seed = options.seed;
    double margin = 0;
    if (options.strip) {
      if (!(stripHeight > 0))
        throw UserError(fmt::format("{}: strip_height: expected a positive number", options.instance));
      nesting.height = stripHeight;
      nesting.spacing = options.spacing.empty() ? 0.0 : lengthOption(options.spacing, "--spacing");
    } else {
      profiles::Bed bed;
      try {
        bed = profiles::findMachine(profiles::loadProfiles(profiles::profileSearchPath()), options.machine).bed;
      } catch (const profiles::ProfileError&) {
        if (options.machine != "workshop-32x18") throw;  // the default bed of SPEC otherwise
      }
      if (!options.bed.empty()) {
        const auto x = options.bed.find('x');
        if (x == std::string::npos)
          throw UserError(fmt::format("--bed {}: expected WIDTHxHEIGHT, e.g. 32x18 or 812.8mmx457.2mm", options.bed));
        bed.width = lengthOption(options.bed.substr(0, x), "--bed");
        bed.height = lengthOption(options.bed.substr(x + 1), "--bed");
      }
      if (!options.margin.empty()) bed.margin = lengthOption(options.margin, "--margin");
      if (2 * bed.margin >= std::min(bed.width, bed.height)) {
        throw UserError(
            fmt::format("--margin {}: leaves no usable area on a {} x {} bed", bed.margin, bed.width, bed.height));
      }
      margin = bed.margin;
      nesting.width = bed.width - 2 * bed.margin;
      nesting.height = bed.height - 2 * bed.margin;
      nesting.spacing = options.spacing.empty() ? 0.0625 : lengthOption(options.spacing, "--spacing");
    }
    if (options.order == "strict")
      nesting.order = jobs::OrderMode::Strict;
    else if (options.order == "window")
      nesting.order = jobs::OrderMode::Window;
    else
      nesting.order = jobs::OrderMode::Free;
    nesting.window = options.window;
    if (!options.json) nesting.progress = [](const std::string& line) { fmt::print(stderr, "nest: {}\n", line); };

    jobs::NestingResult result;
    try {
      result = jobs::nest(parts, nesting);
    } catch (const std::invalid_argument& error) {
      throw UserError(fmt::format("{}: {}", options.instance, error.what()));
    }
    const auto problems = jobs::layoutProblems(parts, result, nesting);
    if (!problems.empty()) {
      fmt::print(stderr, "error: internal: the layout failed its own check: {}\n", problems.front());
      return kUserError;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::ordered_json summary;
    summary["sheets"] = result.sheets;
    summary["utilization"] =
        options.strip ? nlohmann::ordered_json(nullptr)
                      : nlohmann::ordered_json(result.partArea / (result.sheets * nesting.width * nesting.height));
    summary["strip_length"] =
        options.strip ? nlohmann::ordered_json(result.stripLength) : nlohmann::ordered_json(nullptr);
    summary["density"] = options.strip ? nlohmann::ordered_json(result.partArea / (nesting.height * result.stripLength))
                                       : nlohmann::ordered_json(nullptr);
    summary["seconds"] = seconds;

    if (!options.out.empty()) {
      std::filesystem::create_directories(options.out);
      nlohmann::ordered_json layout = {{"placements", nlohmann::ordered_json::array()}};
      std::vector<int> copyOfPart(parts.size());
      for (size_t p = 0, i = 0; i < items.size(); ++i)
        for (int c = 0; c < items[i].demand; ++c, ++p) copyOfPart[p] = c;
      std::vector<int> itemOfPart;
      for (const auto& item : items)
        for (int c = 0; c < item.demand; ++c) itemOfPart.push_back(item.id);
      for (size_t cut = 0; cut < result.placements.size(); ++cut) {
        const auto& p = result.placements[cut];
        layout["placements"].push_back({{"item", itemOfPart[p.part]},
                                        {"copy", copyOfPart[p.part]},
                                        {"sheet", p.sheet},
                                        {"x", p.x + margin},
                                        {"y", p.y + margin},
                                        {"rotation", p.rotation},
                                        // Extension: how far the layout moved the part from its order in the file.
                                        {"moved", static_cast<int>(cut) - parts[p.part].order}});
      }
      jobs::writeFileAtomically(std::filesystem::path(options.out) / "layout.json", layout.dump(1) + "\n");
      jobs::writeFileAtomically(std::filesystem::path(options.out) / "layout.svg",
                                layoutSvg(parts, result, nesting, margin));
    }
    if (options.json) {
      std::cout << summary.dump() << '\n';
    } else if (options.strip) {
      fmt::print("{} parts in a strip {:.4g} long and {:.4g} high: density {:.1f}% ({} layouts tried in {:.1f} s)\n",
                 parts.size(), result.stripLength, nesting.height, 100.0 * summary["density"].get<double>(),
                 result.evaluations, seconds);
    } else {
      fmt::print("{} parts on {} sheet{}: utilization {:.1f}% ({} layouts tried in {:.1f} s)\n", parts.size(),
                 result.sheets, result.sheets == 1 ? "" : "s", 100.0 * summary["utilization"].get<double>(),
                 result.evaluations, seconds);
    }
    return kSuccess;
  } catch (const UserError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  } catch (const profiles::ProfileError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  } catch (const std::exception& error) {
    fmt::print(stderr, "error: {}: {}\n", options.instance, error.what());
    return kUserError;
  }
}

}  // namespace

void addNestCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<NestOptions>();
  CLI::App* command = app.add_subcommand("nest", "Nest the parts of an instance file onto beds or into a strip");
  command->add_option("INSTANCE", options->instance, "Instance file (jagua-rs / sparrow JSON)")->required();
  command->add_option("--bed", options->bed, "Bed size WIDTHxHEIGHT (default: the machine profile's, 32x18 in)");
  command->add_option("--margin", options->margin, "Margin on every side of the bed (default: the profile's, 1/4 in)");
  command->add_option("--machine", options->machine, "Machine profile for the bed")->capture_default_str();
  command->add_option("--spacing", options->spacing, "Least distance between parts (default 1/16 in; 0 with --strip)");
  command->add_flag("--strip", options->strip, "Nest into one strip of the instance's strip_height, least length");
  command->add_option("--time", options->seconds, "Improvement time budget in seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  command->add_option("--order", options->order, "strict, window or free: how far parts may move from their order")
      ->capture_default_str()
      ->check(CLI::IsMember({"strict", "window", "free"}));
  command->add_option("--window", options->window, "With --order window: at most this many places")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the improvement search")->capture_default_str();
  command->add_option("--out", options->out, "Folder for layout.json and layout.svg");
  command->add_flag("--json", options->json,
                    "Print one JSON object: sheets, utilization, strip_length, density, seconds");
  command->footer(
      "Lengths take in, mm or cm (a bare number is inches). In bin mode utilization is part area over the usable\n"
      "area of all sheets; in strip mode density is part area over strip_height x strip_length.\n\n"
      "Examples:\n"
      "  rotafab nest parts.json --out layout/\n"
      "  rotafab nest ../shared/benchmarks/esicup/shirts.json --strip --time 60 --json");
  command->callback([options, &status] { status = runNest(*options); });
}

}  // namespace rotafab::cli
