#pragma once
// What the API hands the queue for a submission (Service::submit).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "daemon/service/Spool.h"

namespace rotafab::service {

struct Submission {
  std::string owner;
  std::string device;  // empty: any device whose machine profile fits
  int priority = 0;
  std::vector<std::string> options;  // `make` options, as command-line words
  // An upload: the mesh, already written into a spool entry of its own
  // under `fileName` (cleaned: ApiInput.h's cleanFileName)...
  std::optional<Spool::Entry> upload;
  std::string fileName;
  // ...or a path on the daemon's machine: a mesh file or a `make` output folder.
  std::filesystem::path path;
};

}  // namespace rotafab::service
