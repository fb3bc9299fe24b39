#include "daemon/ManifestCommand.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "daemon/CommandSupport.h"
#include "jobs/Manifest.h"
#include "jobs/ManifestFile.h"

namespace rotafab::cli {
namespace {

int runManifest(const std::string& folder, const std::string& format) {
  try {
    const nlohmann::json manifest = jobs::readManifest(folder);
    if (format == "json") {
      std::cout << manifest.dump(1) << '\n';
      return kSuccess;
    }
    std::filesystem::path file(folder);
    if (std::filesystem::is_directory(file)) file /= "manifest.json";
    try {
      std::cout << (format == "html" ? jobs::manifestHtml(manifest, file.parent_path()) : jobs::manifestText(manifest));
    } catch (const std::invalid_argument& error) {
      throw UserError(fmt::format("{}: {}", file.string(), error.what()));
    }
    return kSuccess;
  } catch (const UserError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  }
}

}  // namespace

void addManifestCommand(CLI::App& app, int& status) {
  auto folder = std::make_shared<std::string>();
  auto format = std::make_shared<std::string>("text");
  CLI::App* manifest = app.add_subcommand("manifest", "Print the assembly manifest of a `make` output folder");
  manifest->add_option("DIR", *folder, "The output folder of `rotafab make` (or its manifest.json)")->required();
  manifest
      ->add_option("--format", *format, "text (the steps), json (manifest.json) or html (steps and sheets, to print)")
      ->capture_default_str()
      ->check(CLI::IsMember({"text", "json", "html"}));
  manifest->footer(
      "Examples:\n"
      "  rotafab manifest bunny-band/\n"
      "  rotafab manifest bunny-band/ --format html > bunny.html");
  manifest->callback([folder, format, &status] { status = runManifest(*folder, *format); });
}

}  // namespace rotafab::cli
