#include "core/ProgramFolders.h"

namespace rotafab::core {

std::filesystem::path programFolder() {
  std::error_code error;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : self.parent_path();
}

std::filesystem::path installedDataFolder() { return programFolder().parent_path() / "share" / "rotafab"; }

std::filesystem::path installedHelperFolder() { return programFolder().parent_path() / "libexec" / "rotafab"; }

}  // namespace rotafab::core
