#include "jobs/ManifestFile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/UserError.h"
#include "jobs/JsonErrors.h"

namespace rotafab::jobs {

nlohmann::ordered_json readManifest(const std::filesystem::path& folderOrFile) {
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
  std::ifstream in(file, std::ios::binary);
  if (!in) throw core::UserError(fmt::format("{}: cannot read it: {}", file.string(), std::strerror(errno)));
  // Read whole, then parsed: nlohmann's parser reads a string several times faster than a stream.
  std::string text;
  in.seekg(0, std::ios::end);
  text.resize(static_cast<size_t>(std::max<std::streamoff>(0, in.tellg())));
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (!in) throw core::UserError(fmt::format("{}: cannot read it: {}", file.string(), std::strerror(errno)));
  try {
    return nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::json::parse_error& error) {
    throw core::UserError(fmt::format("{}: not JSON: {}", file.string(), jsonErrorText(error)));
  }
}

}  // namespace rotafab::jobs
