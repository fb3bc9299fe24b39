#include "cli/MakeOptionsCli.h"

#include <fmt/format.h>

#include <string>
#include <vector>

#include "cli/CommandSupport.h"

namespace rotafab::cli {
namespace {

// The table's own check of a value, as CLI11 runs it.
CLI::Validator tableCheck(const jobs::MakeOption& option) {
  std::string shown;
  switch (option.value) {
    case jobs::OptionValue::Fraction:
      shown = "0<F<=1";
      break;
    case jobs::OptionValue::Formats:
      shown = "eps,svg,dxf";
      break;
    default:
      break;
  }
  return CLI::Validator([&option](std::string& value) { return jobs::whyNotAValue(option, value); }, shown);
}

}  // namespace

void addMakeOptions(CLI::App& make, MakeOptions& options) {
  make.add_option("MESH", options.mesh, "Mesh file: OBJ, OFF, PLY, STL, glTF/GLB, 3MF, ...")->required();
  std::map<std::string_view, CLI::Option*> declared;
  for (const jobs::MakeOption& option : jobs::makeOptionTable()) {
    const std::string flag = fmt::format("--{}", option.name);
    const std::string help(option.help);
    CLI::Option* added = std::visit(
        [&](auto member) -> CLI::Option* {
          using Field = std::remove_cvref_t<decltype(options.*member)>;
          if constexpr (std::is_same_v<Field, bool>) {
            return make.add_flag(flag, options.*member, help);
          } else {
            return make.add_option(flag, options.*member, help);
          }
        },
        option.member);
    if (option.showDefault) added->capture_default_str();
    switch (option.value) {
      case jobs::OptionValue::Choice: {
        std::vector<std::string> choices(option.choices.begin(), option.choices.end());
        added->check(CLI::IsMember(choices));
        break;
      }
      case jobs::OptionValue::Number:
      case jobs::OptionValue::Whole:
        if (option.least != option.most) {
          if (option.value == jobs::OptionValue::Whole) {
            added->check(CLI::Range(static_cast<int>(option.least), static_cast<int>(option.most)));
          } else {
            added->check(CLI::Range(option.least, option.most));
          }
        }
        break;
      case jobs::OptionValue::Fraction:
      case jobs::OptionValue::Formats:
        added->check(tableCheck(option));
        break;
      case jobs::OptionValue::Text:
      case jobs::OptionValue::Length:
      case jobs::OptionValue::Flag:
        break;
    }
    declared[option.name] = added;
  }
  declared["structure"]->required();
  declared["out"]->check(outputFolderCheck());
  for (const jobs::MakeOption& option : jobs::makeOptionTable()) {
    if (!option.excludes.empty()) declared[option.name]->excludes(declared[option.excludes]);
  }
}

void checkStructureOptions(const CLI::App& make, MakeOptions& options) {
  for (const jobs::MakeOption& option : jobs::makeOptionTable()) {
    if (make.count(fmt::format("--{}", option.name)) > 0) options.given.insert(std::string(option.name));
  }
  try {
    jobs::checkStructureOptions(options);
  } catch (const jobs::OptionError& error) {
    throw CLI::ValidationError(error.what());
  }
}

}  // namespace rotafab::cli
