#include "toolpath/ManifestFile.h"

#include <fmt/format.h>

#include <simdjson.h>
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <optional>

#include "core/UserError.h"
#include "toolpath/JsonErrors.h"

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

std::string kitLine(std::optional<std::pair<int, int>> run, int completes) {
  std::string steps;
  if (run)
    steps = run->first == run->second ? fmt::format("step {}; ", run->first)
                                      : fmt::format("steps {}-{}; ", run->first, run->second);
  return steps + (completes > 0 ? fmt::format("once cut, steps 1-{} can be done", completes)
                                : std::string("no step can be done yet"));
}

std::optional<ManifestSheets> readManifestSheets(const std::filesystem::path& manifestFile) {
  simdjson::padded_string text;
  if (simdjson::padded_string::load(manifestFile.string()).get(text) != simdjson::SUCCESS) return std::nullopt;
  // One parser per thread, kept: a new one maps and unmaps its buffers on
  // every call, and each unmap stops the other core to flush its TLB. One
  // that grew for a large manifest is let go, not kept for the daemon's life.
  constexpr size_t kKeptCapacity = 1 << 20;
  thread_local std::optional<simdjson::dom::parser> kept;
  if (!kept) kept.emplace();
  simdjson::dom::parser& parser = *kept;
  struct LetGoIfGrown {
    std::optional<simdjson::dom::parser>& kept;
    ~LetGoIfGrown() {
      if (kept->capacity() > kKeptCapacity) kept.reset();
    }
  } letGo{kept};
  simdjson::dom::element manifest;
  simdjson::dom::array sheets;
  if (parser.parse(text).get(manifest) != simdjson::SUCCESS || manifest["sheets"].get(sheets) != simdjson::SUCCESS)
    return std::nullopt;
  ManifestSheets read;
  for (simdjson::dom::element sheet : sheets) {
    int64_t index = 0;
    simdjson::dom::array files;
    if (sheet["index"].get(index) != simdjson::SUCCESS || sheet["files"].get(files) != simdjson::SUCCESS)
      return std::nullopt;
    for (simdjson::dom::element file : files) {
      std::string_view name;
      if (file.get(name) != simdjson::SUCCESS || index < 1 || index > INT32_MAX) return std::nullopt;
      if (name.ends_with(".svg")) read.svgSheets.emplace_back(static_cast<int>(index), std::string(name));
    }
    // (Optional keys: manifests before kits have neither.)
    int64_t completes = 0;
    simdjson::dom::array kit;
    if (sheet["completes"].get(completes) == simdjson::SUCCESS) {
      std::optional<std::pair<int, int>> run;
      if (int64_t first = 0, last = 0; sheet["kit"].get(kit) == simdjson::SUCCESS && kit.size() == 2 &&
                                       kit.at(0).get(first) == simdjson::SUCCESS &&
                                       kit.at(1).get(last) == simdjson::SUCCESS) {
        run = {static_cast<int>(first), static_cast<int>(last)};
      }
      read.kits[static_cast<int>(index)] = kitLine(run, static_cast<int>(completes));
    }
  }
  if (simdjson::dom::array panels; manifest["panels"].get(panels) == simdjson::SUCCESS) read.panels = panels.size();
  if (simdjson::dom::element cost; manifest["cost"].get(cost) == simdjson::SUCCESS) read.cost = simdjson::minify(cost);
  // (Manifests before these keys name neither.)
  if (std::string_view name; manifest["machine"].get(name) == simdjson::SUCCESS) read.machine = std::string(name);
  if (std::string_view name; manifest["material"].get(name) == simdjson::SUCCESS) read.material = std::string(name);
  if (std::string_view name; manifest["display_units"].get(name) == simdjson::SUCCESS)
    read.displayUnits = std::string(name);
  return read;
}

}  // namespace rotafab::jobs
