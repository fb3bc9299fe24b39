#include "daemon/service/ServiceImpl.h"

namespace rotafab::service {

namespace {

// An action the job's state does not allow: 409, saying the state and why.
[[noreturn]] void refuse(const JobRecord& job, const std::string& why) {
  throw ApiError(409, fmt::format("job {} is {}{}", job.id, stateName(job.state), why));
}

// A device with no head to frame with (a print spool): 409, saying so.
void refuseUnlessItFrames(const DeviceConfig& device) {
  if (!devices::parseDeviceUri(device.uri).driver->frames()) {
    throw ApiError(
        409, fmt::format("{} writes files for a print driver and moves no head to frame a sheet with", device.name));
  }
}

}  // namespace

Reply Service::Impl::act(JobId id, const std::string& action, const json& arguments, const std::string& who) {
  if (stopping) throw ApiError(503, "the daemon is stopping");
  const JobRecord job = jobOrThrow(id);
  // A cut or plan of this host's is stopped whatever the store says of its
  // job (released to another host meanwhile, the laser must still go off).
  const bool frameOnly = cuts.contains(id) && cuts.at(id)->frameOnly;
  if (action == "cancel" && !frameOnly && (cuts.contains(id) || planning.contains(id)) && store->shared() &&
      !(job.host == config.host && heldByAHost(job.state))) {
    if (auto c = cuts.find(id); c != cuts.end()) cancelCut(*c->second, who);
    if (auto p = planning.find(id); p != planning.end()) p->second.cancel->cancel();
    return {202, jobJson(job)};
  }
  if (store->shared() && (!joined || leaseLost) && (action == "start" || action == "resume")) {
    throw ApiError(503, fmt::format("host {} lost its lease on the job store and is joining it again; ask again in a "
                                    "moment",
                                    config.host));
  }
  // A job another host is planning or cutting is that host's to act on
  // (its driver, its planner): the action is left for it in the store,
  // and it acts within half a second (Impl::serveRequests).
  if (heldByAHost(job.state) && !job.host.empty() && job.host != config.host &&
      (action == "cancel" || action == "pause" || action == "resume" || action == "next" || action == "frame")) {
    return askItsHost(job, action, arguments, who);
  }
  // (Held by this host, a job is in `planning` or `cuts` until it leaves that state.)
  const bool ours = job.host.empty() || job.host == config.host;
  if (ours &&
      ((job.state == JobState::Planning && !planning.contains(id)) || (holdsDevice(job.state) && !cuts.contains(id)))) {
    refuse(job, ", but this daemon is not working on it (it is being released); ask again in a moment");
  }
  if (action == "cancel") return cancelJob(job, who);
  if (action == "pause") return pauseJob(job, who);
  if (action == "resume") return resumeJob(job, arguments, who);
  if (action == "start") {
    if (job.state != JobState::Ready) {
      refuse(job, job.state == JobState::Queued || job.state == JobState::Planning
                      ? "; it can start once it is planned"
                      : "; only a ready job can be started");
    }
    startCut(job, 1, fmt::format("started by {}", who));
    return {200, jobJson(store->job(id).value())};
  }
  if (action == "next") return nextSheet(job, who);
  if (action == "frame") return frameJob(job, arguments, who);
  if (action == "move") return moveJob(job, arguments, who);
  throw ApiError(404, fmt::format("no action {} (cancel, pause, resume, start, next, move, frame)", action));
}

void Service::Impl::cancelCut(Cut& cut, const std::string& who) {
  cut.cancelledBy = who;
  // (A paused job stays held: the driver sees the cancel in its hold and
  // stops from there, without moving again.)
  cut.control->cancel.cancel();
  if (cut.waiting) {
    cut.waiting->set_value(devices::SheetGo::Stop);
    cut.waiting.reset();
  }
}

Reply Service::Impl::askItsHost(const JobRecord& job, const std::string& action, const json& arguments,
                                const std::string& who) {
  if (action == "pause" && job.state != JobState::Running) refuse(job, "; only a running job can be paused");
  if (action == "resume" && job.state != JobState::Paused) {
    refuse(job, "; only a paused, interrupted or failed job can be resumed");
  }
  if ((action == "next" || action == "frame") && job.state != JobState::Running) {
    refuse(job, "; only a job waiting between sheets takes `next`");
  }
  ActionRequest request;
  request.job = job.id;
  request.action = action;
  request.arguments = arguments.is_null() ? "{}" : arguments.dump();
  request.who = who;
  if (const auto holder = store->requestAction(request)) {
    json answer = jobJson(job);
    answer["asked_host"] = *holder;
    store->addEvent(job.id, "asked", fmt::format("{} asked host {} to {} it", who, *holder, action));
    return {202, answer};
  }
  return act(job.id, action, arguments, who);  // (released to no host, or to this one, meanwhile)
}

Reply Service::Impl::cancelJob(const JobRecord& job, const std::string& who) {
  const JobId id = job.id;
  if (job.state == JobState::Planning) {
    planning[id].cancelledBy = who;
    planning[id].cancel->cancel();
    return {202, jobJson(job)};
  }
  if (holdsDevice(job.state)) {
    cancelCut(*cuts.at(id), who);
    return {202, jobJson(job)};
  }
  if (auto c = cuts.find(id); c != cuts.end()) cancelCut(*c->second, who);  // its frame, stopped
  if (job.state == JobState::Done || job.state == JobState::Cancelled) refuse(job, "; there is nothing to cancel");
  const JobRecord cancelled = record(id, JobState::Cancelled, fmt::format("cancelled by {}", who));
  jobChanged(cancelled);
  pump();
  return {200, jobJson(cancelled)};
}

Reply Service::Impl::pauseJob(const JobRecord& job, const std::string& who) {
  if (job.state != JobState::Running) refuse(job, "; only a running job can be paused");
  Cut& cut = *cuts.at(job.id);
  if (cut.waiting) refuse(job, ", waiting for the next sheet: nothing moves, so there is nothing to pause");
  if (cut.between) refuse(job, ", between sheets (one starting or being framed): pause once it cuts");
  if (auto* run = cut.control->run.load()) run->pause();
  const JobRecord paused = record(job.id, JobState::Paused, fmt::format("paused by {}", who));
  devices[cut.device].state = "paused";
  deviceChanged(devices[cut.device]);
  jobChanged(paused);
  return {200, jobJson(paused)};
}

Reply Service::Impl::resumeJob(const JobRecord& job, const json& arguments, const std::string& who) {
  const JobId id = job.id;
  if (job.state == JobState::Paused) {
    Cut& cut = *cuts.at(id);
    if (auto* run = cut.control->run.load()) run->resume();
    const JobRecord running = record(id, JobState::Running, fmt::format("resumed by {}", who));
    devices[cut.device].state = "running";
    deviceChanged(devices[cut.device]);
    jobChanged(running);
    return {200, jobJson(running)};
  }
  if (job.state != JobState::Interrupted && job.state != JobState::Failed) {
    refuse(job, "; only a paused, interrupted or failed job can be resumed");
  }
  if (job.sheets == 0) refuse(job, "; it was never planned: submit it again");
  if (!arguments.contains("from_sheet") || !arguments["from_sheet"].is_number_integer()) {
    throw ApiError(400, fmt::format("job {} stopped {}: say which sheet to go on from, once that sheet is loaded", id,
                                    sheetWhere(job.sheet, job.sheets, job.stroke, job.strokes)));
  }
  const int from = arguments["from_sheet"].get<int>();
  // The sheet it stopped in goes on from the first stroke not cut (framed
  // first, and only once its operator says it is in place); `from_stroke`
  // 1 cuts it whole again.
  int64_t fromStroke = from == job.sheet && job.stroke > 0 && job.stroke < job.strokes ? job.stroke : 0;
  if (arguments.contains("from_stroke")) {
    if (from != job.sheet && arguments["from_stroke"].get<int64_t>() != 1) {
      throw ApiError(
          400, fmt::format("job {} stopped in sheet {}: sheet {} goes on from its first stroke", id, job.sheet, from));
    }
    fromStroke = arguments["from_stroke"].get<int64_t>() - 1;
    if (fromStroke >= job.strokes && job.strokes > 0) {
      throw ApiError(400,
                     fmt::format("sheet {} of job {} has {} strokes, not {}", from, id, job.strokes, fromStroke + 1));
    }
  }
  startCut(job, from,
           fromStroke > 0 ? fmt::format("resumed by {} from sheet {}, stroke {}", who, from, fromStroke + 1)
                          : fmt::format("resumed by {} from sheet {}", who, from),
           fromStroke);
  return {200, jobJson(store->job(id).value())};
}

Reply Service::Impl::frameJob(const JobRecord& job, const json& arguments, const std::string& who) {
  const JobId id = job.id;
  if (auto c = cuts.find(id); c != cuts.end()) {
    // Being cut: only between sheets, by its own cut, and only the sheet it waits for.
    Cut& cut = *c->second;
    if (!cut.waiting) {
      refuse(job, cut.frameOnly ? fmt::format(", and its sheet {} is being framed", cut.sheet)
                                : fmt::format(", cutting sheet {} of {}: a sheet is framed before its cut, while the "
                                              "job waits for it",
                                              job.sheet, job.sheets));
    }
    refuseUnlessItFrames(devices[cut.device].config);
    if (arguments.contains("sheet") && arguments["sheet"].get<int>() != cut.sheet) {
      throw ApiError(
          409, fmt::format("job {} waits for {}; only sheet {} can be framed now", id, cut.waitingFor, cut.sheet));
    }
    if (job.state != JobState::Running) refuse(job, "; only a job waiting between sheets is framed by its cut");
    cut.waiting->set_value(devices::SheetGo::Frame);
    cut.waiting.reset();
    cut.waitingFor.clear();
    store->addEvent(id, "frame", fmt::format("{} asked for a frame of sheet {}", who, cut.sheet));
    jobChanged(job);
    json answer = jobJson(job);
    answer["framing_sheet"] = cut.sheet;
    answer["frame_light"] = profiles::frameLight(devices[cut.device].machine.framePower);
    return {202, answer};
  }
  if (holdsDevice(job.state) || job.state == JobState::Queued || job.state == JobState::Planning ||
      job.state == JobState::Done || job.sheets == 0) {
    refuse(job, job.state == JobState::Done ? "; its sheets are cut" : "; only a planned job's sheets can be framed");
  }
  const int sheet = arguments.contains("sheet") ? arguments["sheet"].get<int>() : std::max(1, job.sheet);
  if (sheet > job.sheets) throw ApiError(400, fmt::format("job {} has sheets 1 to {}, not {}", id, job.sheets, sheet));
  Device& device = idleDeviceFor(job);
  refuseUnlessItFrames(device.config);
  store->addEvent(id, "frame", fmt::format("{} asked for a frame of sheet {} on {}", who, sheet, device.config.name));
  launchCut(job, device, sheet, 0, true);
  json answer = jobJson(store->job(id).value());
  answer["frame_light"] = profiles::frameLight(device.machine.framePower);
  return {202, answer};
}

Reply Service::Impl::nextSheet(const JobRecord& job, const std::string& who) {
  auto c = cuts.find(job.id);
  if (c == cuts.end() || !c->second->waiting) {
    refuse(job, job.state == JobState::Running ? fmt::format(", cutting sheet {} of {}: it is not waiting for the "
                                                             "next sheet",
                                                             job.sheet, job.sheets)
                                               : std::string("; only a job waiting between sheets takes `next`"));
  }
  if (job.state != JobState::Running) refuse(job, "; only a job waiting between sheets takes `next`");
  c->second->between = true;
  c->second->waiting->set_value(devices::SheetGo::Cut);
  c->second->waiting.reset();
  c->second->waitingFor.clear();
  store->addEvent(job.id, "next", fmt::format("{} said sheet {} is in place", who, c->second->sheet));
  return {200, jobJson(job)};
}

Reply Service::Impl::moveJob(const JobRecord& job, const json& arguments, const std::string& who) {
  const JobId id = job.id;
  if (isFinal(job.state) && job.state != JobState::Interrupted && job.state != JobState::Failed) {
    refuse(job, "; only a job still to cut has a place in the queue");
  }
  if (arguments.contains("device")) return moveToDevice(job, arguments["device"].get<std::string>(), who);
  int priority = job.priority;
  if (arguments.contains("priority")) {
    if (!arguments["priority"].is_number_integer()) throw ApiError(400, "priority: expected a whole number");
    priority = arguments["priority"].get<int>();
  }
  double position = job.position;
  if (arguments.contains("before")) {
    if (!arguments["before"].is_number_integer()) throw ApiError(400, "before: expected a job number");
    const JobRecord other = jobOrThrow(arguments["before"].get<JobId>());
    if (other.id == id) throw ApiError(400, "a job cannot move before itself");
    priority = other.priority;
    // Halfway between the other job and the one before it in the queue.
    double previous = other.position - 1;
    for (const JobRecord& candidate : store->jobs()) {
      if (candidate.priority == priority && candidate.position < other.position && candidate.id != id) {
        previous = std::max(previous, candidate.position);
      }
    }
    position = (previous + other.position) / 2;
  } else if (!arguments.contains("priority")) {
    throw ApiError(400, "move needs before (a job number), priority (a whole number) or device (a device's name)");
  }
  store->reorder(id, priority, position);
  store->addEvent(id, "move", fmt::format("moved by {}", who));
  const JobRecord moved = store->job(id).value();
  jobChanged(moved);
  return {200, jobJson(moved)};
}

Reply Service::Impl::moveToDevice(const JobRecord& job, const std::string& name, const std::string& who) {
  const JobId id = job.id;
  if (job.state != JobState::Queued && job.state != JobState::Ready && job.state != JobState::Interrupted &&
      job.state != JobState::Failed) {
    refuse(job, "; only a job waiting to be planned or cut, or one stopped mid-way, moves to another device");
  }
  if (cuts.contains(id)) refuse(job, ", and its sheet is being framed; move it once the frame is done");
  std::string why;
  const std::optional<Target> target = deviceFor(name, job.options, why);
  if (!target) throw ApiError(409, why);
  // The machine its sheets were planned for, where they were.
  const std::string planned = summaryText(job, "machine");
  if (!planned.empty() && planned != target->machine.name) {
    if (job.state != JobState::Ready || job.kind != JobKind::Mesh) {
      refuse(job, fmt::format(", its sheets planned for {}{}; {} is a {}: a device of {} can cut them", planned,
                              job.kind == JobKind::Mesh ? " and partly cut" : " (a folder is cut as it was made)", name,
                              target->machine.name, planned));
    }
    // Planned again for the other machine's bed and settings.
    JobChange change;
    change.device = name;
    record(id, JobState::Queued,
           fmt::format("moved by {} to {} (a {}): to be planned again for it", who, name, target->machine.name),
           change);
    store->setDevice(id, name);
    store->addEvent(id, "move", fmt::format("moved by {} to {}", who, name));
    jobChanged(store->job(id).value());
    pump();
    return {200, jobJson(store->job(id).value())};
  }
  store->setDevice(id, name);
  store->addEvent(id, "move",
                  fmt::format("moved by {} from {} to {}", who, job.device.empty() ? "any device" : job.device, name));
  const JobRecord moved = store->job(id).value();
  jobChanged(moved);
  pump();
  return {200, jobJson(moved)};
}

}  // namespace rotafab::service
