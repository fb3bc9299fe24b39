#include "daemon/service/JobStore.h"

#include <fmt/format.h>

#include <chrono>

namespace rotafab::service {

std::string_view kindName(JobKind kind) { return kind == JobKind::Planned ? "planned" : "mesh"; }

double unixSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

void checkFirstSteps(const std::vector<NewJob>& jobs) {
  for (const NewJob& job : jobs) {
    JobState state = JobState::Queued;
    for (const FirstStep& step : job.then) {
      if (!allowedTransition(state, step.to)) {
        throw TransitionRefused(
            fmt::format("a new job of {} cannot go from {} to {}", job.source, stateName(state), stateName(step.to)));
      }
      state = step.to;
    }
  }
}

void checkHolder(const JobRecord& job, const std::string& host) {
  if (heldByAHost(job.state) && !job.host.empty() && job.host != host) {
    throw TransitionRefused(
        fmt::format("job {} is {} on host {}; only that host can move it now", job.id, stateName(job.state), job.host));
  }
}

std::vector<JobId> moveRows(const std::vector<JobRecord>& jobs, const ClaimDecision& decide, JobRows& rows) {
  const double at = unixSeconds();
  std::vector<JobId> moved;
  for (const JobRecord& job : jobs) {
    const std::optional<Claim> decided = decide(job);
    if (!decided) continue;
    rows.move(job.id, job.state, decided->to, at, decided->reason);
    rows.apply(job.id, decided->change);
    moved.push_back(job.id);
  }
  return moved;
}

ClaimDecision releasing(const Release& release, const HostRecord& host) {
  return [release, host](const JobRecord& job) {
    auto [to, reason] = release(job, host);
    return std::optional<Claim>(Claim{to, std::move(reason), {}});
  };
}

std::vector<JobId> addJobRows(const std::vector<NewJob>& jobs, const std::vector<std::string>& reasons,
                              double lastPosition, JobRows& rows) {
  const double at = unixSeconds();
  std::vector<JobId> ids;
  for (size_t i = 0; i < jobs.size(); ++i) {
    const NewJob& job = jobs[i];
    const JobId id = rows.insertRow(job, lastPosition + static_cast<double>(i + 1), at);
    ids.push_back(id);
    rows.record(id, std::nullopt, JobState::Queued, at, reasons.at(i));
    JobState state = JobState::Queued;
    for (const FirstStep& step : job.then) {
      rows.move(id, state, step.to, at, step.reason ? step.reason(id) : std::string());
      state = step.to;
    }
    if (!job.then.empty()) rows.apply(id, job.change);
  }
  return ids;
}

}  // namespace rotafab::service
