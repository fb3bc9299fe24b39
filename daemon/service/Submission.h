#pragma once
// What the API hands the queue for a submission (Service::submit).

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "daemon/service/Spool.h"
#include "jobs/MakeOptions.h"

namespace rotafab::service {

struct Submission {
  std::string owner;
  std::string device;  // empty: any device whose machine profile fits
  int priority = 0;
  std::optional<jobs::MakeOptions> options;  // a mesh's `make` options (none given: none)
  // An upload: the mesh, already written into a spool entry of its own
  // under `fileName` (cleaned: ApiInput.h's cleanFileName)...
  std::optional<Spool::Entry> upload;
  std::string fileName;
  // ...or a path on the daemon's machine: a mesh file or a `make` output folder.
  std::filesystem::path path;
};

// The `make` options of a submission, read by make's own table
// (jobs/MakeOptions.h): an object of option names and values ({"structure":
// "band", "score-folds": true}), or a JSON array of command-line words. None
// for null or an empty list or object. Throws ApiError(400) "make options: ...".
std::optional<jobs::MakeOptions> makeOptionsOf(const nlohmann::json& options);

}  // namespace rotafab::service
