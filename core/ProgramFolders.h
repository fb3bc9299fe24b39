#pragma once
// Where the running program's own files are: its folder, and its data
// folder as `cmake --install` lays it out (PREFIX/bin/rotafab beside
// PREFIX/share/rotafab and PREFIX/libexec/rotafab), wherever PREFIX is.

#include <filesystem>
#include <string>

namespace rotafab::core {

// The folder of the running program (empty when it cannot be told).
std::filesystem::path programFolder();

// PREFIX/share/rotafab for a program in PREFIX/bin: the shipped profiles
// (profiles/) and fonts (fonts/).
std::filesystem::path installedDataFolder();

// PREFIX/libexec/rotafab: the helper programs.
std::filesystem::path installedHelperFolder();

// The helper program `name`: beside the running program (the build tree),
// else in installedHelperFolder(), else the bare name (found on the PATH, or
// the error of starting it names the program that is missing).
std::string helperProgram(const std::string& name);

// The value of the environment variable `name`, empty when it is not set.
std::string environmentValue(const char* name);

// $HOME, else /tmp.
std::filesystem::path homeFolder();

// The daemon's state folder by default: $XDG_STATE_HOME/rotafab, else
// ~/.local/state/rotafab (both programs: the daemon keeps its state there,
// the command line finds the daemon's socket from it).
std::filesystem::path defaultStateDir();

// The daemon's socket by default: $XDG_RUNTIME_DIR/rotafab/rotafabd.sock,
// else rotafabd.sock in `stateDir`.
std::filesystem::path defaultSocket(const std::filesystem::path& stateDir);

}  // namespace rotafab::core
