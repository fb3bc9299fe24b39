#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

std::string sheetWhere(int sheet, int sheets, int64_t stroke, int64_t strokes) {
  if (sheet <= 0) return "before the first sheet";
  return fmt::format("at sheet {} of {}, after stroke {} of {}", sheet, sheets, stroke, strokes);
}

JobChange Service::Impl::cutFromSheet(int fromSheet, const std::string& device) {
  JobChange change;
  change.device = device;
  change.sheet = fromSheet;
  change.stroke = 0;
  change.strokes = 0;
  return change;
}

auto Service::Impl::localDeviceFor(const JobRecord& job) -> Device& {
  if (Device* own = deviceNamed(job.device)) return *own;
  std::string why;
  const std::optional<Target> planned = deviceFor(job.device, "", why);
  if (job.anyDevice && planned) {
    Device* idle = nullptr;
    for (Device& device : devices) {
      if (device.machine.name != planned->machine.name) continue;
      if (!idle || (device.state == "idle" && !device.job)) idle = &device;
    }
    if (idle) return *idle;
  }
  for (const DeviceRecord& device : store->devices()) {
    if (device.name != job.device) continue;
    const bool gone = device.state == "gone";
    throw ApiError(409, fmt::format("job {} is for {}, a device of host {}{}{}: start it there{}", job.id, job.device,
                                    device.host, gone ? ", which is gone" : "",
                                    gone ? "" : hostAddressSaid(device.host), gone ? " once it runs again" : ""));
  }
  throw ApiError(409, fmt::format("job {}: there is no device {} now", job.id, job.device));
}

void Service::Impl::startCut(const JobRecord& job, int fromSheet, const std::string& reason) {
  if (diskFull) throw ApiError(507, diskFullRefusal());
  Device* device = &localDeviceFor(job);
  if (device->job) {
    throw ApiError(409, fmt::format("{} is busy with job {}; job {} can start once it is done", device->config.name,
                                    *device->job, job.id));
  }
  if (device->state == "checking") {
    // The client waits and asks again (`retry_after`): a start that waited here would begin
    // a cut after its operator had perhaps given up on it.
    throw ApiError(409,
                   fmt::format("{} is still being checked (connected, stopped, its laser off confirmed); "
                               "start job {} again in a moment",
                               device->config.name, job.id),
                   {{"retry_after", 0.25}, {"device", device->config.name}});
  }
  if (device->state == "offline") {
    throw ApiError(409, fmt::format("{} is {}{}", device->config.name, device->state,
                                    device->message.empty() ? "" : ": " + device->message));
  }
  if (fromSheet < 1 || fromSheet > job.sheets) {
    throw ApiError(400, fmt::format("job {} has sheets 1 to {}, not {}", job.id, job.sheets, fromSheet));
  }
  launchCut(record(job.id, JobState::Running, reason, cutFromSheet(fromSheet, device->config.name)), *device,
            fromSheet);
}

void Service::Impl::launchCut(const JobRecord& job, Device& on, int fromSheet) {
  Device* device = &on;
  const size_t index = static_cast<size_t>(device - devices.data());
  auto cut = std::make_unique<Cut>();
  cut->control = std::make_shared<RunControl>();
  cut->device = index;
  cut->firstSheet = fromSheet;
  device->job = job.id;
  device->state = "running";
  device->message.clear();
  const fs::path folder = plannedFolder(job);
  Cut& started = *cut;
  {
    std::lock_guard lock(heldMutex);
    heldCuts[job.id] = cut->control;
  }
  cuts[job.id] = std::move(cut);
  started.thread =
      std::thread([this, id = job.id, control = started.control, uri = device->config.uri, machine = device->machine,
                   material = device->material, folder, fromSheet,
                   sheets = job.sheets] { runCut(id, control, uri, machine, material, folder, fromSheet, sheets); });
  log->info("job {}: cutting on {} from sheet {}", job.id, device->config.name, fromSheet);
  jobChanged(job);
  deviceChanged(*device);
}

profiles::MaterialProfile Service::Impl::cuttingMaterial(const fs::path& folder,
                                                         const profiles::MaterialProfile& device) const {
  const jobs::JobProfileNames madeFor = jobs::jobProfileNames(folder);
  if (!madeFor.material || *madeFor.material == device.name) return device;
  return profiles::findMaterial(catalogue, *madeFor.material);
}

void Service::Impl::runCut(JobId id, const std::shared_ptr<RunControl>& control, const std::string& uri,
                           const profiles::MachineProfile& machine, const profiles::MaterialProfile& material,
                           const fs::path& folder, int fromSheet, int sheets) {
  std::optional<devices::DeviceFault> fault;
  std::optional<std::string> failure;
  devices::RunSummary summary;
  // Destroyed on the strand, once the strand can no longer reach it through control->run.
  std::shared_ptr<devices::JobRun> owned;
  try {
    devices::JobRunSetup setup;
    setup.device = devices::parseDeviceUri(uri);
    setup.machine = machine;
    setup.material = cuttingMaterial(folder, material);
    for (const jobs::JobSheet& sheet : jobs::readJobSheets(folder, std::nullopt)) {
      if (sheet.index >= fromSheet) setup.sheets.push_back(sheet.drawing);
    }
    setup.cancellation = &control->cancel;
    owned = std::make_shared<devices::JobRun>(std::move(setup));
    devices::JobRun& run = *owned;
    control->run = &run;
    devices::RunEvents events;
    events.beforeSheet = [this, id, control](const jobs::Toolpath&) {
      std::promise<bool> loaded;
      std::future<bool> answer = loaded.get_future();
      onStrand([this, id, control, loaded = std::make_shared<std::promise<bool>>(std::move(loaded))]() mutable {
        auto c = cuts.find(id);
        if (c == cuts.end() || control->cancel.cancelled()) {
          loaded->set_value(false);
          return;
        }
        c->second->waiting.emplace(std::move(*loaded));
        try {
          const JobRecord job = store->job(id).value();
          store->addEvent(id, "waiting",
                          fmt::format("sheet {} cut; waiting for sheet {} to be loaded", job.sheet, job.sheet + 1));
          jobChanged(job);
        } catch (const std::exception& error) {
          storeTrouble(fmt::format("job {}", id), error);
        }
      });
      return answer.get();
    };
    // The sheet being cut, in the job's numbering (the run's own counts from fromSheet).
    auto current = std::make_shared<std::atomic<int>>(fromSheet);
    events.sheetStarted = [this, id, fromSheet, sheets, current](size_t index, const jobs::Toolpath& toolpath,
                                                                 double seconds) {
      const int sheet = fromSheet + static_cast<int>(index);
      *current = sheet;
      const auto strokes = static_cast<int64_t>(toolpath.strokes.size());
      onStrand([this, id, sheet, sheets, strokes, seconds] {
        auto c = cuts.find(id);
        if (c == cuts.end()) return;
        c->second->progress = {{"job", id},   {"phase", "cutting"}, {"sheet", sheet},         {"sheets", sheets},
                               {"stroke", 0}, {"strokes", strokes}, {"seconds_left", seconds}};
        JobChange change;
        change.sheet = sheet;
        change.stroke = 0;
        change.strokes = strokes;
        try {
          store->update(id, change);
          store->addEvent(id, "sheet", fmt::format("sheet {} of {} started", sheet, sheets));
          jobChanged(store->job(id).value());
        } catch (const std::exception& error) {
          storeTrouble(fmt::format("job {}", id), error);
        }
      });
    };
    events.progress = [this, id, sheets, current](const devices::Progress& progress) {
      onStrand([this, id, progress, sheet = current->load(), sheets] { cutProgress(id, progress, sheet, sheets); });
    };
    summary = run.run(false, events, control->cancel);
    control->run = nullptr;
  } catch (const devices::DeviceFault& caught) {
    control->run = nullptr;
    fault = caught;
    if (fault->sheet > 0) fault->sheet += fromSheet - 1, fault->sheets = sheets;
  } catch (const std::exception& error) {
    control->run = nullptr;
    failure = inSubmittersWords(error.what(), folder);
  }
  onStrand([this, id, fault, failure, summary, owned = std::move(owned)]() mutable {
    cutEnded(id, fault, failure, summary);
    owned.reset();  // disconnects the device
  });
}

void Service::Impl::cutProgress(JobId id, const devices::Progress& progress, int sheet, int sheets) {
  auto c = cuts.find(id);
  if (c == cuts.end()) return;
  Cut& cut = *c->second;
  cut.progress = {{"job", id},
                  {"phase", "cutting"},
                  {"sheet", sheet},
                  {"sheets", sheets},
                  {"stroke", progress.stroke},
                  {"strokes", progress.strokes},
                  {"seconds_left", progress.secondsLeft}};
  const auto now = Clock::now();
  // The store is told at most once a second: enough to say after a kill
  // where the cut had got to, without a synced write per stroke.
  if (now - cut.lastStored >= std::chrono::seconds(1)) {
    cut.lastStored = now;
    JobChange change;
    change.sheet = sheet;
    change.stroke = static_cast<int64_t>(progress.stroke);
    change.strokes = static_cast<int64_t>(progress.strokes);
    try {
      store->update(id, change);
    } catch (const std::exception& error) {
      // (Its progress no longer kept, a cut on a full disk stops: a kill would lose where it was.)
      storeTrouble(fmt::format("job {}", id), error);
    }
  }
  if (now - cut.lastSent >= std::chrono::milliseconds(200) || progress.stroke == progress.strokes) {
    cut.lastSent = now;
    publish("progress", cut.progress);
  }
}

void Service::Impl::cutEnded(JobId id, const std::optional<devices::DeviceFault>& fault,
                             const std::optional<std::string>& failure, const devices::RunSummary& summary) {
  auto c = cuts.find(id);
  if (c == cuts.end()) return;
  std::unique_ptr<Cut> cut = std::move(c->second);
  cuts.erase(c);
  {
    std::lock_guard lock(heldMutex);
    heldCuts.erase(id);
  }
  if (cut->thread.joinable()) cut->thread.join();
  Device& device = devices[cut->device];
  device.job.reset();
  device.state = "idle";
  try {
    const JobRecord job = store->job(id).value();
    JobRecord ended;
    if (!fault && !failure) {
      JobChange change;
      change.sheet = job.sheets;
      change.stroke = job.strokes;
      ended = record(
          id, JobState::Done,
          fmt::format("cut on {}: {} sheet{} from sheet {}, {} strokes, {:.1f} in burnt", device.config.name,
                      summary.sheets, summary.sheets == 1 ? "" : "s", cut->firstSheet, summary.strokes, summary.burnt),
          change, true);
    } else if (failure) {
      // (Not the device's fault: a sheet or a profile; the device stays idle.)
      ended = record(id, JobState::Failed, *failure, {}, true);
    } else {
      JobChange change;
      if (fault->sheet > 0) {
        change.sheet = fault->sheet;
        change.stroke = static_cast<int64_t>(fault->strokesDone);
        change.strokes = static_cast<int64_t>(fault->strokes);
      }
      const std::string where =
          fault->sheet == 0    ? std::string("before the first sheet")
          : fault->nothingSent ? fmt::format("at sheet {} of {}, before any of it was sent", fault->sheet, job.sheets)
                               : sheetWhere(fault->sheet, job.sheets, static_cast<int64_t>(fault->strokesDone),
                                            static_cast<int64_t>(fault->strokes));
      const std::string laser = devices::laserStateAfter(*fault);
      // The sheet it stopped at, or where this cut began when it stopped before any.
      const int goOn = fault->sheet > 0 ? fault->sheet : std::max(1, cut->firstSheet);
      if (fault->kind == devices::FaultKind::Cancelled && cut->control->shutdown) {
        const std::string stopped = cut->stoppedBecause.empty() ? std::string("the daemon stopped")
                                                                : cut->stoppedBecause + ": the daemon stopped the cut";
        ended =
            record(id, JobState::Interrupted,
                   fmt::format("{} {}; {}; to go on, load sheet {} and resume from it", stopped, where, laser, goOn),
                   change, true);
      } else if (fault->kind == devices::FaultKind::Cancelled) {
        ended = record(
            id, JobState::Cancelled,
            fmt::format("cancelled{} {}; {}", cut->cancelledBy.empty() ? "" : " by " + cut->cancelledBy, where, laser),
            change, true);
      } else {
        device.state = "fault";
        device.message = fault->what();
        ended =
            record(id, JobState::Failed,
                   fmt::format("{} ({}; stopped {}; {}); to go on once it is fixed, load sheet {} and resume from it",
                               fault->what(), devices::faultName(fault->kind), where, laser, goOn),
                   change, true);
      }
    }
    log->info("job {}: {}: {}", id, stateName(ended.state), ended.message);
    jobChanged(ended);
  } catch (const std::exception& error) {
    log->error("job {}: {}", id, error.what());
  }
  deviceChanged(device);
  finishIfStopping();
  pump();
}

void Service::Impl::finishIfStopping() {
  if (!stopping || !cuts.empty() || !planning.empty() || !stopped) return;
  auto done = std::move(stopped);
  stopped = nullptr;
  done();
}

}  // namespace rotafab::service
