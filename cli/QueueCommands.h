#pragma once
// The verbs that talk to the fabrication daemon (docs/CONTRACT.md, "Command line"):
// submit, jobs, status, cancel, pause, resume, start, next, frame, move; and
// the daemon's side of `devices --daemon` and `manifest JOB`. How their jobs
// are shown: JobViews.h.

#include <CLI/CLI.hpp>
#include <string>

namespace rotafab::cli {

void addQueueCommands(CLI::App& app, int& status);

// `rotafab devices --daemon`: the daemon's devices and their states.
int runDaemonDevices(bool json, const std::string& server, const std::string& token);

// `rotafab manifest JOB`: the manifest of a planned job, from the daemon.
int runDaemonManifest(long long job, const std::string& format, const std::string& server, const std::string& token,
                      const std::string& units);

}  // namespace rotafab::cli
