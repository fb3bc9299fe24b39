#pragma once
// Runs a piece of work in a child process, so that a library that aborts,
// crashes or hangs on hostile input (Debian's Assimp 5.2 is built with its
// assertions on and aborts on some malformed files) cannot take the caller
// down with it. The work returns bytes; they come back through a pipe.

#include <chrono>
#include <functional>
#include <string>

#include "core/Cancellation.h"

namespace rotafab::geometry {

struct IsolatedResult {
  enum class Status { Finished, Crashed, TimedOut };
  Status status = Status::Crashed;
  std::string output;  // what the work returned (Finished only)
  int signal = 0;      // the signal that ended the child (Crashed), 0 if it exited
};

// The child's standard error goes to /dev/null: a library's own messages must
// not reach the user's terminal. An exception escaping `work` counts as a crash.
// A cancel (checked every 100 ms) kills the child and throws core::Cancelled.
IsolatedResult runIsolated(const std::function<std::string()>& work, std::chrono::milliseconds timeout,
                           const core::Cancellation* cancellation = nullptr);

}  // namespace rotafab::geometry
