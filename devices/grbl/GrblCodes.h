#pragma once
// GRBL 1.1's error and alarm numbers, in words (from the meanings in gnea/grbl's
// doc/markdown/interface.md, written anew): what `error:N` and `ALARM:N` mean.

#include <string>

namespace rotafab::devices::grbl {

std::string errorMessage(int code);
std::string alarmMessage(int code);

}  // namespace rotafab::devices::grbl
