#include "cli/ManifestCommand.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "cli/CommandSupport.h"
#include "cli/QueueCommands.h"
#include "jobs/Manifest.h"
#include "toolpath/ManifestFile.h"

namespace rotafab::cli {
namespace {

int runManifest(const std::string& folder, const std::string& format, const std::string& units) {
  try {
    const nlohmann::ordered_json manifest = jobs::readManifest(folder);
    if (format == "json") {
      std::cout << jobs::manifestJsonText(manifest);
      return kSuccess;
    }
    std::filesystem::path file(folder);
    if (std::filesystem::is_directory(file)) file /= "manifest.json";
    try {
      const core::LengthUnit unit = unitShown(units, jobs::displayUnitOf(manifest));
      std::cout << (format == "html" ? jobs::manifestHtml(manifest, file.parent_path(), unit)
                                     : jobs::manifestText(manifest, unit));
    } catch (const std::invalid_argument& error) {
      throw UserError(fmt::format("{}: {}", file.string(), error.what()));
    }
    return kSuccess;
  } catch (const UserError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  } catch (const profiles::ProfileError& error) {  // the user's settings
    fmt::print(stderr, "error: {}\n", error.what());
    return kUserError;
  }
}

}  // namespace

void addManifestCommand(CLI::App& app, int& status) {
  auto folder = std::make_shared<std::string>();
  auto format = std::make_shared<std::string>("text");
  auto server = std::make_shared<std::string>();
  auto token = std::make_shared<std::string>();
  auto units = std::make_shared<std::string>();
  CLI::App* manifest =
      app.add_subcommand("manifest", "Print the assembly manifest of a `make` output folder or of a daemon's job");
  manifest
      ->add_option("DIR", *folder,
                   "The output folder of `rotafab make` (or its manifest.json), or a job's number on the daemon")
      ->required();
  manifest->add_option("--server", *server, "For a job: the daemon, unix:PATH or http://HOST:PORT");
  manifest->add_option("--token", *token, "For a job: the bearer token a TCP listener asks for");
  manifest
      ->add_option("--format", *format, "text (the steps), json (manifest.json) or html (steps and sheets, to print)")
      ->capture_default_str()
      ->check(CLI::IsMember({"text", "json", "html"}));
  addUnitsOption(manifest, *units);
  manifest->footer(
      "Examples:\n"
      "  rotafab manifest bunny-band/\n"
      "  rotafab manifest bunny-band/ --format html > bunny.html\n"
      "  rotafab manifest bunny-band/ --units mm # its lengths in millimetres\n"
      "  rotafab manifest 7                      # job 7 on the daemon");
  manifest->callback([folder, format, server, token, units, &status] {
    // A number that is not a folder here is a job of the daemon's.
    const bool number = !folder->empty() && folder->find_first_not_of("0123456789") == std::string::npos;
    if (number && !std::filesystem::exists(*folder)) {
      status = runDaemonManifest(std::stoll(*folder), *format, *server, *token, *units);
      return;
    }
    status = runManifest(*folder, *format, *units);
  });
}

}  // namespace rotafab::cli
