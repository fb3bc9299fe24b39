#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

std::string sheetWhere(int sheet, int sheets, int64_t stroke, int64_t strokes) {
  if (sheet <= 0) return "before the first sheet";
  return fmt::format("at sheet {} of {}, with {} of its {} strokes cut", sheet, sheets, stroke, strokes);
}

std::string goOnSaid(int sheet, int64_t cut, int64_t strokes) {
  if (cut > 0 && cut < strokes) {
    return fmt::format(
        "leave sheet {} where it is and resume from it: it is framed, then goes on from stroke {} once "
        "you say it is in place",
        sheet, cut + 1);
  }
  return fmt::format("load sheet {} and resume from it", sheet);
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

auto Service::Impl::idleDeviceFor(const JobRecord& job) -> Device& {
  if (diskFull) throw ApiError(507, diskFullRefusal());
  Device* device = &localDeviceFor(job);
  if (device->job && device->state == "framing") {
    throw ApiError(409, fmt::format("{} is framing a sheet of job {}; ask again once the frame is done",
                                    device->config.name, *device->job));
  }
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
  return *device;
}

void Service::Impl::startCut(const JobRecord& job, int fromSheet, const std::string& reason, int64_t fromStroke) {
  Device& device = idleDeviceFor(job);
  if (fromSheet < 1 || fromSheet > job.sheets) {
    throw ApiError(400, fmt::format("job {} has sheets 1 to {}, not {}", job.id, job.sheets, fromSheet));
  }
  JobChange change = cutFromSheet(fromSheet, device.config.name);
  change.stroke = fromStroke;
  launchCut(record(job.id, JobState::Running, reason, change), device, fromSheet, fromStroke);
}

void Service::Impl::launchCut(const JobRecord& job, Device& on, int fromSheet, int64_t fromStroke, bool frameOnly) {
  if (cuts.contains(job.id)) {
    throw ApiError(409, fmt::format("job {} is being framed; ask again once the frame is done", job.id));
  }
  Device* device = &on;
  const size_t index = static_cast<size_t>(device - devices.data());
  auto cut = std::make_unique<Cut>();
  cut->control = std::make_shared<RunControl>();
  cut->device = index;
  cut->firstSheet = fromSheet;
  cut->frameOnly = frameOnly;
  cut->sheet = fromSheet;
  // A frame leaves the device as it found it (a fault the operator checks stays one).
  cut->stateBefore = device->state, cut->messageBefore = device->message;
  device->job = job.id;
  device->state = frameOnly ? "framing" : "running";
  device->message.clear();
  CutSetup setup{device->config.uri, device->machine, device->material, plannedFolder(job),
                 fromSheet,          job.sheets,      fromStroke,       frameOnly};
  Cut& started = *cut;
  {
    std::lock_guard lock(heldMutex);
    heldCuts[job.id] = cut->control;
  }
  cuts[job.id] = std::move(cut);
  started.thread = std::thread(
      [this, id = job.id, control = started.control, setup = std::move(setup)] { runCut(id, control, setup); });
  if (frameOnly) {
    log->info("job {}: framing sheet {} on {}", job.id, fromSheet, device->config.name);
  } else {
    log->info("job {}: cutting on {} from sheet {}{}", job.id, device->config.name, fromSheet,
              fromStroke > 0 ? fmt::format(", stroke {}", fromStroke + 1) : "");
  }
  jobChanged(job);
  deviceChanged(*device);
}

profiles::MaterialProfile Service::Impl::cuttingMaterial(const fs::path& folder,
                                                         const profiles::MaterialProfile& device) const {
  const jobs::JobProfileNames madeFor = jobs::jobProfileNames(folder);
  if (!madeFor.material || *madeFor.material == device.name) return device;
  return profiles::findMaterial(catalogue, *madeFor.material);
}

devices::SheetGo Service::Impl::waitForOperator(JobId id, const std::shared_ptr<RunControl>& control, int sheet,
                                                const std::string& what) {
  std::promise<devices::SheetGo> told;
  std::future<devices::SheetGo> answer = told.get_future();
  onStrand([this, id, control, sheet, what,
            told = std::make_shared<std::promise<devices::SheetGo>>(std::move(told))]() mutable {
    auto c = cuts.find(id);
    if (c == cuts.end() || control->cancel.cancelled()) {
      told->set_value(devices::SheetGo::Stop);
      return;
    }
    c->second->waiting.emplace(std::move(*told));
    c->second->waitingFor = what;
    c->second->sheet = sheet;
    try {
      store->addEvent(id, "waiting", fmt::format("waiting for {}", what));
      const JobRecord job = store->job(id).value();
      jobChanged(job);
      // The operator is needed at the machine: a sheet to load, or a framed one to check.
      json extra = {{"waiting_for", what}, {"waiting_sheet", sheet}};
      if (const std::string stock = summaryText(job, "stock"); !stock.empty()) extra["stock"] = stock;
      notify(job, what.find("framed") == std::string::npos ? "load_sheet" : "sheet_framed", extra);
    } catch (const std::exception& error) {
      storeTrouble(fmt::format("job {}", id), error);
    }
  });
  return answer.get();
}

void Service::Impl::runCut(JobId id, const std::shared_ptr<RunControl>& control, const CutSetup& cutSetup) {
  std::optional<devices::DeviceFault> fault;
  std::optional<std::string> failure;
  devices::RunSummary summary;
  const int fromSheet = cutSetup.fromSheet, sheets = cutSetup.sheets;
  const auto fromStroke = static_cast<size_t>(std::max<int64_t>(cutSetup.fromStroke, 0));
  // Destroyed on the strand, once the strand can no longer reach it through control->run.
  std::shared_ptr<devices::JobRun> owned;
  try {
    devices::JobRunSetup setup;
    setup.device = devices::parseDeviceUri(cutSetup.uri);
    setup.machine = cutSetup.machine;
    setup.material = cuttingMaterial(cutSetup.folder, cutSetup.material);
    for (const jobs::JobSheet& sheet : jobs::readJobSheets(cutSetup.folder, std::nullopt)) {
      if (cutSetup.frameOnly ? sheet.index == fromSheet : sheet.index >= fromSheet) {
        setup.sheets.push_back(sheet.drawing);
      }
    }
    setup.fromStroke = fromStroke;
    setup.cancellation = &control->cancel;
    owned = std::make_shared<devices::JobRun>(std::move(setup));
    devices::JobRun& run = *owned;
    if (cutSetup.frameOnly) {
      onStrand([this, id] {
        if (auto c = cuts.find(id); c != cuts.end()) {
          c->second->progress = {{"job", id}, {"phase", "framing"}, {"sheet", c->second->sheet}};
          publish("progress", c->second->progress);
        }
      });
      run.frameOnly(0, control->cancel);
    } else {
      control->run = &run;
      devices::RunEvents events;
      // Between sheets, the operator says the next is loaded (or asks for
      // its frame); a sheet that goes on mid-way is framed first, and waits
      // for the operator to see it in place.
      events.beforeSheet = [this, id, control, fromStroke](size_t index, const jobs::Toolpath& sheet, bool framed) {
        using devices::SheetGo;
        if (index == 0 && fromStroke == 0 && !framed) return SheetGo::Cut;
        if (index == 0 && !framed) return SheetGo::Frame;
        if (index == 0 || framed) {
          return waitForOperator(id, control, sheet.sheet,
                                 fromStroke > 0 && index == 0
                                     ? fmt::format("sheet {} framed: once it is in place, go on from stroke {}",
                                                   sheet.sheet, fromStroke + 1)
                                     : fmt::format("sheet {} framed: once it is in place, cut it", sheet.sheet));
        }
        return waitForOperator(id, control, sheet.sheet, fmt::format("sheet {} to be loaded", sheet.sheet));
      };
      events.framing = [this, id](const jobs::Toolpath&) {
        onStrand([this, id] {
          if (auto c = cuts.find(id); c != cuts.end()) {
            c->second->between = true;
            c->second->progress["phase"] = "framing";
            publish("progress", c->second->progress);
          }
        });
      };
      events.sheetStarted = [this, id, sheets](size_t, const jobs::Toolpath& toolpath, size_t first, double seconds) {
        const int sheet = toolpath.sheet;
        const auto strokes = static_cast<int64_t>(toolpath.strokes.size());
        onStrand([this, id, sheet, sheets, strokes, first, seconds] {
          auto c = cuts.find(id);
          if (c == cuts.end()) return;
          c->second->between = false;
          c->second->progress = {{"job", id},       {"phase", "cutting"}, {"sheet", sheet},         {"sheets", sheets},
                                 {"stroke", first}, {"strokes", strokes}, {"seconds_left", seconds}};
          JobChange change;
          change.sheet = sheet;
          change.stroke = static_cast<int64_t>(first);
          change.strokes = strokes;
          try {
            store->update(id, change);
            store->addEvent(id, "sheet",
                            first > 0 ? fmt::format("sheet {} of {} goes on from stroke {}", sheet, sheets, first + 1)
                                      : fmt::format("sheet {} of {} started", sheet, sheets));
            jobChanged(store->job(id).value());
          } catch (const std::exception& error) {
            storeTrouble(fmt::format("job {}", id), error);
          }
        });
      };
      events.progress = [this, id, sheets](const devices::Progress& progress) {
        onStrand([this, id, progress, sheets] { cutProgress(id, progress, sheets); });
      };
      summary = run.run(events, control->cancel);
      control->run = nullptr;
    }
  } catch (const devices::DeviceFault& caught) {
    control->run = nullptr;
    fault = caught;
    if (fault->sheet > 0) fault->sheets = sheets;
  } catch (const std::exception& error) {
    control->run = nullptr;
    failure = inSubmittersWords(error.what(), cutSetup.folder);
  }
  onStrand([this, id, fault, failure, summary, owned = std::move(owned)]() mutable {
    cutEnded(id, fault, failure, summary);
    owned.reset();  // disconnects the device
  });
}

void Service::Impl::cutProgress(JobId id, const devices::Progress& progress, int sheets) {
  auto c = cuts.find(id);
  if (c == cuts.end()) return;
  Cut& cut = *c->second;
  cut.progress = {{"job", id},
                  {"phase", "cutting"},
                  {"sheet", progress.sheet},
                  {"sheets", sheets},
                  {"stroke", progress.stroke},
                  {"cut", progress.strokesCut},
                  {"strokes", progress.strokes},
                  {"seconds_left", progress.secondsLeft}};
  const auto now = Clock::now();
  // The strokes cut are stored as they grow, at most ten times a second,
  // and at the sheet's end (a sheet cut whole counts as cut): after a kill
  // the job goes on from a stroke no more than a few behind the cut (a
  // stroke takes tens of milliseconds at least), without a synced write for each.
  const auto cutNow = static_cast<int64_t>(progress.strokesCut);
  if (cutNow != cut.storedCut &&
      (now - cut.lastStored >= std::chrono::milliseconds(100) || progress.strokesCut == progress.strokes)) {
    cut.lastStored = now;
    cut.storedCut = cutNow;
    JobChange change;
    change.sheet = progress.sheet;
    change.stroke = cutNow;
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
  if (cut->frameOnly) {
    frameEnded(id, *cut, device, fault, failure);
    return;
  }
  try {
    const JobRecord job = store->job(id).value();
    JobRecord ended;
    if (!fault && !failure) {
      JobChange change;
      change.sheet = job.sheets;
      change.stroke = job.strokes;
      // In the job's unit (its summary's "units"), else the daemon's.
      const core::LengthUnit unit =
          core::LengthUnit::named(summaryText(job, "units")).value_or(config.units.value_or(core::LengthUnit()));
      ended = record(
          id, JobState::Done,
          fmt::format("cut on {}: {} sheet{} from sheet {}, {} strokes, {} burnt", device.config.name, summary.sheets,
                      summary.sheets == 1 ? "" : "s", cut->firstSheet, summary.strokes, unit(summary.burnt, 1)),
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
          fault->sheet == 0 ? std::string("before the first sheet")
          : fault->nothingSent && fault->strokesDone == 0
              ? fmt::format("at sheet {} of {}, before any of it was sent", fault->sheet, job.sheets)
              : sheetWhere(fault->sheet, job.sheets, static_cast<int64_t>(fault->strokesDone),
                           static_cast<int64_t>(fault->strokes));
      const std::string laser = devices::laserStateAfter(*fault);
      // The sheet it stopped at, or where this cut began when it stopped before any.
      const std::string goOn = fault->sheet > 0 ? goOnSaid(fault->sheet, static_cast<int64_t>(fault->strokesDone),
                                                           static_cast<int64_t>(fault->strokes))
                                                : goOnSaid(std::max(1, cut->firstSheet), 0, 0);
      if (fault->kind == devices::FaultKind::Cancelled && cut->control->shutdown) {
        const std::string stopped = cut->stoppedBecause.empty() ? std::string("the daemon stopped")
                                                                : cut->stoppedBecause + ": the daemon stopped the cut";
        ended = record(id, JobState::Interrupted, fmt::format("{} {}; {}; to go on, {}", stopped, where, laser, goOn),
                       change, true);
      } else if (fault->kind == devices::FaultKind::Cancelled) {
        ended = record(
            id, JobState::Cancelled,
            fmt::format("cancelled{} {}; {}", cut->cancelledBy.empty() ? "" : " by " + cut->cancelledBy, where, laser),
            change, true);
      } else {
        device.state = "fault";
        device.message = fault->what();
        ended = record(id, JobState::Failed,
                       fmt::format("{} ({}; stopped {}; {}); to go on once it is fixed, {}", fault->what(),
                                   devices::faultName(fault->kind), where, laser, goOn),
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

void Service::Impl::frameEnded(JobId id, const Cut& cut, Device& device,
                               const std::optional<devices::DeviceFault>& fault,
                               const std::optional<std::string>& failure) {
  // The job stays as it was, and the device: a frame moves the head (the laser off, or at its frame_power).
  device.state = cut.stateBefore, device.message = cut.messageBefore;
  const std::string light = profiles::frameLight(device.machine.framePower);
  std::string said = fmt::format("sheet {} framed on {} ({})", cut.sheet, device.config.name, light);
  if (failure) said = fmt::format("sheet {} not framed: {}", cut.sheet, *failure);
  // (A frame at a marking power lit the laser: what is true of it now, as after a cut.)
  const auto laserAfter = [&] {
    return device.machine.framePower > 0 ? devices::laserStateAfter(*fault) : std::string("the laser was not lit");
  };
  if (fault && fault->kind == devices::FaultKind::Cancelled) {
    said = fmt::format("framing sheet {} stopped{}; {}", cut.sheet,
                       cut.cancelledBy.empty() ? "" : " by " + cut.cancelledBy, laserAfter());
  } else if (fault) {
    device.state = "fault";
    device.message = fault->what();
    said = fmt::format("framing sheet {} failed: {} ({}); {}", cut.sheet, fault->what(),
                       devices::faultName(fault->kind), laserAfter());
  }
  log->info("job {}: {}", id, said);
  try {
    store->addEvent(id, "frame", said);
    jobChanged(store->job(id).value());
  } catch (const std::exception& error) {
    storeTrouble(fmt::format("job {}", id), error);
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
