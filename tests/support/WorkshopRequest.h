#pragma once
// A `make` request as the README's first command makes it: the workshop's
// 32 x 18 in bed and posterboard, laid out in rows unless asked otherwise.

#include <filesystem>

#include "jobs/MakeJob.h"
#include "profiles/Profiles.h"

namespace rotafab::test {

inline jobs::MakeRequest workshopRequest(const std::filesystem::path& mesh, bool rows = true) {
  const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  jobs::MakeRequest request;
  request.mesh = mesh;
  request.machine = profiles::findMachine(catalogue, "workshop-32x18");
  request.material = profiles::findMaterial(catalogue, "posterboard");
  request.rows = rows;
  return request;
}

}  // namespace rotafab::test
