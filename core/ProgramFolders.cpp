#include "core/ProgramFolders.h"

#include <unistd.h>

#include <cstdlib>

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

std::string environmentValue(const char* name) {
  const char* value = std::getenv(name);
  return value ? value : "";
}

std::filesystem::path homeFolder() {
  const std::string dir = environmentValue("HOME");
  return dir.empty() ? std::filesystem::path("/tmp") : std::filesystem::path(dir);
}

std::filesystem::path defaultStateDir() {
  const std::string state = environmentValue("XDG_STATE_HOME");
  return (state.empty() ? homeFolder() / ".local/state" : std::filesystem::path(state)) / "rotafab";
}

std::filesystem::path defaultSocket(const std::filesystem::path& stateDir) {
  const std::string runtime = environmentValue("XDG_RUNTIME_DIR");
  return runtime.empty() ? stateDir / "rotafabd.sock" : std::filesystem::path(runtime) / "rotafab/rotafabd.sock";
}

}  // namespace rotafab::core
