#pragma once
// How the daemon's jobs are shown at the terminal: the queue's table, a
// job's status with the command that goes on from it, what to load, the
// answer to an action, and a job followed live (`status --follow`), which
// asks for each next sheet at a terminal.

#include <nlohmann/json.hpp>
#include <string>

#include "cli/DaemonClient.h"

namespace rotafab::cli {

// What to load for `sheet`, where the job's summary says it: ", posterboard
// (0.8 mm), 32 x 18 in (its kit: steps 181-364; ...)".
std::string whatToLoad(const nlohmann::json& job, int sheet);

// `rotafab jobs`: the queue as a table.
void printJobs(const nlohmann::json& jobs);

// A job's message with the command that goes on from it ("planned: 3
// sheets; start it with `rotafab start 7`"); the daemon says its own words.
std::string withCommand(const nlohmann::json& job, long long id);

// `rotafab status JOB`.
void printStatus(const nlohmann::json& job);

// Whether a job has settled: done, failed, cancelled, interrupted, or ready
// (planned: an operator starts it).
bool settled(const nlohmann::json& job);

// `rotafab status JOB --follow`: its events until it settles; the exit status.
int follow(const DaemonClient& client, long long id);

// The job as an action (`action`: cancel, frame, ...) left it, or the daemon's answer as it is.
void printAnswer(const nlohmann::json& answer, const std::string& action, bool asJson);

}  // namespace rotafab::cli
