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

}  // namespace rotafab::core
