#include "daemon/service/JobState.h"

#include <array>
#include <utility>

namespace rotafab::service {
namespace {

constexpr std::array<std::pair<JobState, std::string_view>, 9> kNames{{
    {JobState::Queued, "queued"},
    {JobState::Planning, "planning"},
    {JobState::Ready, "ready"},
    {JobState::Running, "running"},
    {JobState::Paused, "paused"},
    {JobState::Done, "done"},
    {JobState::Failed, "failed"},
    {JobState::Cancelled, "cancelled"},
    {JobState::Interrupted, "interrupted"},
}};

}  // namespace

std::string_view stateName(JobState state) {
  for (const auto& [s, name] : kNames) {
    if (s == state) return name;
  }
  return "unknown";
}

std::optional<JobState> stateNamed(std::string_view name) {
  for (const auto& [s, n] : kNames) {
    if (n == name) return s;
  }
  return std::nullopt;
}

const std::vector<JobState>& allStates() {
  static const std::vector<JobState> states = [] {
    std::vector<JobState> all;
    for (const auto& entry : kNames) all.push_back(entry.first);
    return all;
  }();
  return states;
}

bool allowedTransition(JobState from, JobState to) {
  using S = JobState;
  switch (from) {
    case S::Queued:
      return to == S::Planning || to == S::Cancelled;
    case S::Planning:
      return to == S::Ready || to == S::Failed || to == S::Cancelled || to == S::Queued;
    case S::Ready:
      // (Queued again: moved to a device whose machine differs, to be planned for it.)
      return to == S::Running || to == S::Cancelled || to == S::Queued;
    case S::Running:
      return to == S::Paused || to == S::Done || to == S::Failed || to == S::Cancelled || to == S::Interrupted;
    case S::Paused:
      return to == S::Running || to == S::Cancelled || to == S::Failed || to == S::Interrupted;
    case S::Interrupted:
    case S::Failed:
      return to == S::Running || to == S::Cancelled;
    case S::Done:
    case S::Cancelled:
      return false;
  }
  return false;
}

bool holdsDevice(JobState state) { return state == JobState::Running || state == JobState::Paused; }

bool heldByAHost(JobState state) { return state == JobState::Planning || holdsDevice(state); }

bool isFinal(JobState state) {
  return state == JobState::Done || state == JobState::Cancelled || state == JobState::Failed ||
         state == JobState::Interrupted;
}

}  // namespace rotafab::service
