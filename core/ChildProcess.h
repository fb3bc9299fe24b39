#pragma once
// Runs a program in a child process, hands it bytes on its standard input and
// takes back what it writes on its standard output, so that a library that
// aborts, crashes or hangs on hostile input (Debian's Assimp 5.2 is built with
// its assertions on and aborts on some malformed files) cannot take the
// caller down with it.
//
// The child is started with posix_spawn, never a bare fork: after fork() in a
// program with threads (the executor's pool, a daemon's), the child may only
// call async-signal-safe functions (POSIX, fork()), and a library run there
// can hang forever on a lock some other thread held at the moment of the fork.

#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "core/Cancellation.h"

namespace rotafab::core {

struct ChildResult {
  enum class Status { Finished, Crashed, TimedOut };
  Status status = Status::Crashed;
  std::string output;  // what the child wrote (Finished only: it exited with status 0)
  int signal = 0;      // the signal that ended the child (Crashed), 0 if it exited
  int exitCode = 0;    // its exit status (Crashed without a signal; -1 when unknown)
};

// Runs argv[0] (a path, or a name looked up on the PATH) with `input` as its
// standard input and its standard error sent to /dev/null (a library's own
// messages must not reach the user's terminal). The child has default signal
// handling and a process group of its own (a Ctrl-C at the terminal reaches
// the caller, who cancels; it never kills the child behind the caller's
// back), and no descriptor of the caller's but those three. Past `timeout`
// the child is killed (TimedOut); a cancel (checked every 100 ms) kills it
// and throws Cancelled. However it returns, the child has ended and been
// reaped; it is tied to the calling thread for that long (a helper may ask
// to die with it: PR_SET_PDEATHSIG). Throws std::system_error when the
// program cannot be started ("cannot start PROGRAM: ...").
// `environment`: NAME=VALUE entries added to the caller's environment for
// the child (an entry whose name the caller's environment has already is
// not added: the user's setting wins).
ChildResult runChild(const std::vector<std::string>& argv, std::string_view input, std::chrono::milliseconds timeout,
                     const Cancellation* cancellation = nullptr, const std::vector<std::string>& environment = {});

}  // namespace rotafab::core
