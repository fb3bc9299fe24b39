#pragma once
// The exit statuses of both programs (docs/CONTRACT.md, "Command line").

namespace rotafab::core {

enum ExitCode : int {
  kSuccess = 0,
  kUserError = 1,    // bad input: one clear line naming the file, element and what is wrong
  kUsageError = 2,   // bad command line
  kDeviceFault = 3,  // the cutter failed
};

}  // namespace rotafab::core
