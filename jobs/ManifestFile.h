#pragma once
// Reading a job's manifest.json (SPEC, "manifest.json"): for the commands
// that print it and for those that cut the sheets it lists.

#include <filesystem>
#include <nlohmann/json.hpp>

namespace rotafab::jobs {

// A manifest.json, or the one in an output folder. Throws core::UserError
// naming the file or folder when there is none, it cannot be read or it is
// not JSON.
nlohmann::ordered_json readManifest(const std::filesystem::path& folderOrFile);

}  // namespace rotafab::jobs
