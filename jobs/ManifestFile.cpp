#include "jobs/ManifestFile.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/UserError.h"
#include "jobs/JsonErrors.h"

namespace rotafab::jobs {

nlohmann::json readManifest(const std::filesystem::path& folderOrFile) {
  std::filesystem::path file(folderOrFile);
  std::error_code error;
  const auto status = std::filesystem::status(file, error);
  if (status.type() == std::filesystem::file_type::not_found) {
    throw core::UserError(fmt::format("{}: no such folder or file", file.string()));
  }
  if (status.type() == std::filesystem::file_type::directory) {
    file /= "manifest.json";
    if (!std::filesystem::exists(file, error)) {
      throw core::UserError(
          fmt::format("{}: not an output folder of `rotafab make`: it holds no manifest.json", folderOrFile.string()));
    }
  }
  std::ifstream in(file);
  if (!in) throw core::UserError(fmt::format("{}: cannot read it: {}", file.string(), std::strerror(errno)));
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& error) {
    throw core::UserError(fmt::format("{}: not JSON: {}", file.string(), jsonErrorText(error)));
  }
}

}  // namespace rotafab::jobs
