#pragma once
// What the command line's tests share: the program they run and the source
// tree its examples and profiles come from.

#include <filesystem>
#include <string>

namespace rotafab::test {

inline const std::string kCli = ROTAFAB_CLI;
inline const std::filesystem::path kSource = ROTAFAB_SOURCE_DIR;

}  // namespace rotafab::test
