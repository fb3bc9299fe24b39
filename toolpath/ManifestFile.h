#pragma once
// Reading a job's manifest.json (docs/CONTRACT.md,
// "manifest.json (version 1)"): for the commands that print it and for those
// that cut the sheets it lists.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rotafab::jobs {

// A manifest.json, or the one in an output folder. Throws core::UserError
// naming the file or folder when there is none, it cannot be read or it is
// not JSON.
nlohmann::ordered_json readManifest(const std::filesystem::path& folderOrFile);

// What a queue needs of an output folder's manifest: its SVG sheets, in
// order, and what it says of the job. Read without building the document
// (simdjson; the panels' outlines are most of it): on the cube's 12 KB,
// 16 us where readManifest takes 300 us, on every submission of a folder.
struct ManifestSheets {
  std::vector<std::pair<int, std::string>> svgSheets;  // (sheet index, SVG file name)
  std::optional<size_t> panels;                        // the number of panels, when it lists them
  std::optional<std::string> cost;                     // the "cost" object, as JSON text
  // Each sheet's kit, where the manifest says it (by sheet index): "steps
  // 174-352; once cut, steps 1-352 can be done".
  std::map<int, std::string> kits;
  // The machine and material profiles the job was planned for, by name,
  // where the manifest says them: what it is cut with unless the operator
  // says otherwise.
  std::optional<std::string> machine, material;
  // The unit the job's lengths are shown in ("mm" or "in", make's --units), where it says it.
  std::optional<std::string> displayUnits;
};
// A sheet's kit as the operator and the builders read it: "steps 174-352;
// once cut, steps 1-352 can be done" (`run`: its first and last step, when
// they are one run; `completes`: the steps done once it is cut).
std::string kitLine(std::optional<std::pair<int, int>> run, int completes);

// std::nullopt when manifest.json is not as `make` writes it: readManifest
// then says what is wrong, naming the file, the line and the column.
std::optional<ManifestSheets> readManifestSheets(const std::filesystem::path& manifestFile);

}  // namespace rotafab::jobs
