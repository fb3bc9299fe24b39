#include "core/ProgramFolders.h"

#include <unistd.h>

namespace rotafab::core {

std::filesystem::path programFolder() {
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

std::filesystem::path installedDataFolder() { return programFolder().parent_path() / "share" / "rotafab"; }

std::filesystem::path installedHelperFolder() { return programFolder().parent_path() / "libexec" / "rotafab"; }

std::string helperProgram(const std::string& name) {
  const std::filesystem::path folder = programFolder();
  if (folder.empty()) return name;
  for (const auto& candidate : {folder / name, installedHelperFolder() / name}) {
    if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return name;
}

}  // namespace rotafab::core
