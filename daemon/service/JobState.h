#pragma once
// A job's states (docs/CONTRACT.md, "Daemon") and the one table of the moves between
// them. Every change of state goes through the store's transition(), which
// checks it here, so no other code decides what may follow what.

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rotafab::service {

enum class JobState { Queued, Planning, Ready, Running, Paused, Done, Failed, Cancelled, Interrupted };

std::string_view stateName(JobState state);
std::optional<JobState> stateNamed(std::string_view name);
const std::vector<JobState>& allStates();

// Whether a job may go from `from` to `to`:
//   queued      -> planning, cancelled
//   planning    -> ready, failed, cancelled, queued (the daemon stopped mid-plan: planned again)
//   ready       -> running (an operator's start, or auto_start), cancelled
//   running     -> paused, done, failed, cancelled, interrupted
//   paused      -> running, cancelled, failed, interrupted
//   interrupted -> running (resume --from-sheet only), cancelled
//   failed      -> running (resume --from-sheet, once planned), cancelled
// done and cancelled are final.
bool allowedTransition(JobState from, JobState to);

// Whether a job in this state holds its device (one job per device).
bool holdsDevice(JobState state);
// Whether a job in this state is in one host's hands (planning, running,
// paused): that host alone moves it, and it is released if the host dies.
bool heldByAHost(JobState state);
// Whether nothing more happens to a job in this state by itself.
bool isFinal(JobState state);

// A move the table refuses: "job 7 is done; it cannot be started".
class TransitionRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rotafab::service
