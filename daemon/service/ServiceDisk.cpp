#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

std::string Service::Impl::diskFullRefusal() const {
  return fmt::format(
      "{}: nothing new is taken on until there is room again (free some space on it; the daemon "
      "goes on by itself)",
      kDiskFull);
}

void Service::Impl::storeTrouble(const std::string& what, const std::exception& error) {
  if (saysDiskFull(error.what())) return diskBecameFull(error.what());
  log->error("{}: {}", what, error.what());
}

void Service::Impl::stopCutByItself(Cut& cut, const std::string& because) {
  if (cut.stoppedBecause.empty()) cut.stoppedBecause = because;
  cut.control->shutdown = true;
  cut.control->cancel.cancel();
  if (cut.waiting) {
    cut.waiting->set_value(devices::SheetGo::Stop);
    cut.waiting.reset();
  }
}

void Service::Impl::diskBecameFull(const std::string& why) {
  if (diskFull.exchange(true)) return;
  const bool released = reserve && reserve->release();
  log->error(
      "{} ({}){}: {} cut{} stopped, laser off, and left interrupted; {} plan{} queued again; nothing new is "
      "taken on until there is room again",
      kDiskFull, why, released ? "; the daemon's 8 MiB reserve was given back to record what ends" : "", cuts.size(),
      cuts.size() == 1 ? "" : "s", planning.size(), planning.size() == 1 ? "" : "s");
  for (auto& [id, cut] : cuts) stopCutByItself(*cut, std::string(kDiskFull));
  for (auto& [id, plan] : planning) {
    if (plan.cancelledBy.empty()) plan.stoppedBecause = kDiskFull;
    plan.cancel->cancel();
  }
  watchDisk();
}

void Service::Impl::watchDisk() {
  diskTimer.expires_after(std::chrono::seconds(2));
  diskTimer.async_wait([this](const boost::system::error_code& error) {
    if (error) return;
    writeUnrecorded();
    if (reserve->roomy() && reserve->hold()) {
      diskFull = false;
      log->info("the disk that holds the daemon's state has room again: the queue goes on");
      writeUnrecorded();
      pump();
      return;
    }
    watchDisk();
  });
}

JobRecord Service::Impl::record(JobId id, JobState to, const std::string& reason, const JobChange& change,
                                bool keepIfFull) {
  JobRecord recorded = recordInStore(id, to, reason, change, keepIfFull);
  // The ends of a job, told to whoever listens (Notifier.h).
  if (to == JobState::Done || to == JobState::Failed || to == JobState::Interrupted || to == JobState::Cancelled) {
    notify(recorded, std::string("job_") + std::string(stateName(to)), json::object());
  }
  return recorded;
}

JobRecord Service::Impl::recordInStore(JobId id, JobState to, const std::string& reason, const JobChange& change,
                                       bool keepIfFull) {
  if (!unrecorded.contains(id)) {
    try {
      return store->transition(id, to, reason, change);
    } catch (const StoreError& error) {
      if (!saysDiskFull(error.what())) throw;
      diskBecameFull(error.what());
    }
    try {
      return store->transition(id, to, reason, change);
    } catch (const StoreError& error) {
      if (!saysDiskFull(error.what()) || !keepIfFull) throw;
    }
  } else if (!keepIfFull) {
    throw StoreError(
        fmt::format("{}: job {} has a change not yet recorded; ask again once there is room", kDiskFull, id));
  }
  unrecorded[id].push_back({to, reason, change});
  log->error("job {}: {}: not yet recorded ({}): {}", id, stateName(to), kDiskFull, reason);
  return withUnrecorded(store->job(id).value());
}

void Service::Impl::writeUnrecorded() {
  for (auto entry = unrecorded.begin(); entry != unrecorded.end();) {
    auto& [id, changes] = *entry;
    while (!changes.empty()) {
      const Unrecorded change = changes.front();
      try {
        const JobRecord recorded = store->transition(id, change.to, change.reason, change.change);
        changes.erase(changes.begin());
        if (changes.empty()) jobChanged(recorded);
      } catch (const std::exception& error) {
        if (saysDiskFull(error.what())) break;
        log->error("job {}: {}", id, error.what());
        changes.erase(changes.begin());
      }
    }
    entry = changes.empty() ? unrecorded.erase(entry) : std::next(entry);
  }
}

}  // namespace rotafab::service
