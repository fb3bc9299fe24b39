#include "daemon/service/ServiceImpl.h"

#include "profiles/UserSettings.h"

namespace rotafab::service {

std::string inSubmittersWords(std::string message, const fs::path& folder, const fs::path& submitted) {
  const std::string prefix = folder.string() + "/";
  const std::string as = submitted.empty() ? "" : (submitted / "").string();
  for (size_t at = message.find(prefix); at != std::string::npos; at = message.find(prefix, at + as.size())) {
    message.replace(at, prefix.size(), as);
  }
  return message;
}

namespace {

// The notes a plan makes (make's own, naming the mesh by its path in the
// spool), in the daemon's log as "job N: bunny.obj: ...".
class JobNotesSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  // What a plan said, kept for its summary as `make --json` keeps it.
  struct Said {
    std::vector<std::string> notes, warnings;
  };
  JobNotesSink(std::shared_ptr<spdlog::logger> log, const fs::path& folder, std::string job, std::shared_ptr<Said> said)
      : log_(std::move(log)), folder_(folder), job_(std::move(job)), said_(std::move(said)) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& message) override {
    const std::string text = inSubmittersWords(std::string(message.payload.data(), message.payload.size()), folder_);
    log_->log(message.level, "{}: {}", job_, text);
    if (message.level >= spdlog::level::warn) {
      said_->warnings.push_back(text);
    } else if (message.level == spdlog::level::info) {
      said_->notes.push_back(text);
    }
  }
  void flush_() override { log_->flush(); }

 private:
  std::shared_ptr<spdlog::logger> log_;
  fs::path folder_;
  std::string job_;
  std::shared_ptr<Said> said_;
};

// Each sheet's kit, for the operator: "kits"[s - 1] for sheet s ("" where
// the manifest gives none; no "kits" for a manifest written before them).
void addKits(const jobs::ManifestSheets& listed, json& summary) {
  if (listed.kits.empty()) return;
  summary["kits"] = json::array();
  for (const auto& [sheet, svg] : listed.svgSheets) {
    const auto kit = listed.kits.find(sheet);
    summary["kits"].push_back(kit == listed.kits.end() ? "" : kit->second);
  }
}

// What the job is cut on and with, and what the operator loads for each
// sheet ("posterboard (0.031 in), 32 x 18 in"), in the unit the job's
// lengths are shown in ("units"): the page and `rotafab status` say it.
void addStock(const profiles::MachineProfile& machine, const profiles::MaterialProfile& material, double width,
              double height, core::LengthUnit unit, json& summary) {
  summary["machine"] = machine.name;
  summary["material"] = material.name;
  summary["stock"] = jobs::stockOf(material, width, height, unit);
  summary["units"] = unit.name();
}

}  // namespace

void Service::Impl::pump() {
  if (stopping || !joined || leaseLost || diskFull) return;
  try {
    if (planning.size() < config.planners) {
      // Any host plans any job, against its device's profiles wherever that device is.
      std::map<JobId, std::optional<Target>> targets;
      std::map<JobId, std::string> refusals;
      // A job for a device of another host that this host cannot plan for
      // (that host joined since this one last looked, or is away, or has a
      // profile this one lacks) is left queued for a host that can; it
      // fails only when no host has that device.
      std::set<std::string> everyDevice;
      if (store->shared()) {
        for (const DeviceRecord& device : store->devices()) everyDevice.insert(device.name);
      }
      bool lookAgain = false;
      // (More are looked at than are taken, so that jobs left queued do not hold back those behind them.)
      const size_t free = config.planners - planning.size();
      size_t taken = 0;
      const std::vector<JobRecord> claimed =
          store->claim({JobState::Queued, free + 16, "", "", ""}, [&](const JobRecord& job) -> std::optional<Claim> {
            if (taken == free) return std::nullopt;
            std::string why;
            // (A job for any device planned before, by a host since gone, is planned again for any
            // device.)
            const std::string named = job.anyDevice ? "" : job.device;
            std::optional<Target> device = deviceFor(named, job.options, why);
            if (!device && !named.empty() && everyDevice.contains(named)) {
              lookAgain = true;
              return std::nullopt;
            }
            Claim claim{JobState::Planning, "planning", {}};
            if (device) {
              claim.reason = planningReason(*device);
              claim.change.device = device->name;
            }
            // (A job no device can take fails here and takes no planner:
            // the jobs behind it are looked at in this same pass.)
            if (device) ++taken;
            targets[job.id] = std::move(device);
            refusals[job.id] = why;
            return claim;
          });
      if (lookAgain) refreshOthers();
      bool failedAny = false;
      for (const JobRecord& job : claimed) {
        if (const auto& device = targets[job.id]) {
          startPlanning(job, *device);
        } else {
          jobChanged(job);
          jobChanged(record(job.id, JobState::Failed, refusals[job.id], {}, true));
          failedAny = true;
        }
      }
      // More rows than were looked at may wait behind those that failed: looked at next, not at the next submission.
      if (failedAny && planning.size() < config.planners) onStrand([this] { pump(); });
    }
    for (Device& device : devices) {
      if (!device.config.autoStart || device.state != "idle" || device.job) continue;
      // Its own jobs, and those for any device of its machine.
      const std::string reason = fmt::format("started by itself: {} has auto_start", device.config.name);
      const std::vector<JobRecord> claimed =
          store->claim({JobState::Ready, 1, device.config.name, device.machine.name, device.material.name},
                       [&](const JobRecord& job) -> std::optional<Claim> {
                         // (Not one whose sheet is being framed: it waits for its operator.)
                         if (job.sheets < 1 || cuts.contains(job.id)) return std::nullopt;
                         return Claim{JobState::Running, reason, cutFromSheet(1, device.config.name)};
                       });
      for (const JobRecord& job : claimed) {
        try {
          launchCut(job, device, 1, 0);
        } catch (const std::exception& error) {
          // Claimed but not started: not left running with nothing cutting it.
          log->error("job {}: {}", job.id, error.what());
          jobChanged(
              record(job.id, JobState::Failed, fmt::format("its cut could not start: {}", error.what()), {}, true));
        }
      }
    }
  } catch (const std::exception& error) {
    log->error("{}", error.what());
  }
}

auto Service::Impl::targetOf(const Device& device, const std::string& host) -> Target {
  return {device.config.name, host, device.machine, device.material};
}

auto Service::Impl::deviceFor(const std::string& named, const std::string& options, std::string& why,
                              const std::string& madeFor) const -> std::optional<Target> {
  std::vector<Target> all;
  for (const Device& device : devices) all.push_back(targetOf(device, config.host));
  {
    std::lock_guard lock(othersMutex);
    all.insert(all.end(), others.begin(), others.end());
  }
  std::string names;
  for (const Target& target : all) names += (names.empty() ? "" : ", ") + target.name;
  std::string machine = madeFor;
  try {
    if (const auto given = storedOptions(options); given && given->given.contains("machine")) {
      machine = given->machine;
    }
  } catch (const ApiError&) {
    // (Its plan says what is wrong with them.)
  }
  if (!named.empty()) {
    for (const Target& target : all) {
      if (target.name != named) continue;
      // Planned for one machine, cut on another's bed and settings: refused now, not when it fails.
      if (!machine.empty() && target.machine.name != machine) {
        std::string same;
        for (const Target& other : all) {
          if (other.machine.name == machine) same += (same.empty() ? "" : ", ") + other.name;
        }
        why = fmt::format(
            "device {} is a {}, not the {} {}: {}, or name a device of that machine{}", named, target.machine.name,
            machine, madeFor.empty() ? "asked for" : "the folder was made for",
            madeFor.empty() ? fmt::format("leave out the machine (the job is planned for {}'s)", named)
                            : fmt::format("make it again with --machine {}", target.machine.name),
            same.empty() ? fmt::format(" (none here has it; the devices: {})", names) : fmt::format(" ({})", same));
        return std::nullopt;
      }
      return target;
    }
    why = fmt::format("there is no device {} (the devices: {})", named, names);
    return std::nullopt;
  }
  if (all.empty()) {
    why = "the daemon has no devices";
    return std::nullopt;
  }
  for (const Target& target : all) {
    if (machine.empty() || target.machine.name == machine) return target;
  }
  why = fmt::format("no device has the machine profile {} (the devices: {})", machine, names);
  return std::nullopt;
}

std::string Service::Impl::planningReason(const Target& device) {
  return fmt::format("planning against {} ({})", device.name, device.machine.name);
}

std::string Service::Impl::plannedReason(int sheets) {
  // (In the daemon's own words: `rotafab status` adds the command, the page its Start button.)
  return fmt::format("planned: {} sheet{}", sheets, sheets == 1 ? "" : "s");
}

json Service::Impl::planOfFolder(const fs::path& folder, const profiles::MachineProfile& machine,
                                 const profiles::MaterialProfile& material) const {
  json summary;
  std::vector<jobs::JobSheet> planned;
  // The daemon's setting, else the job's own unit, else the machine's bed's
  // (as `run` takes the user's setting before the job's).
  core::LengthUnit unit = profiles::shownUnit("", config.units, "", machine.bed.unit);
  if (const auto listed = jobs::readManifestSheets(folder / "manifest.json")) {
    planned = jobs::readJobSheets(folder, listed->svgSheets);
    if (listed->displayUnits && !config.units) unit = core::LengthUnit::named(*listed->displayUnits).value_or(unit);
    if (listed->panels) summary["panels"] = *listed->panels;
    if (listed->cost) summary["cost"] = json::parse(*listed->cost);
    addKits(*listed, summary);
  } else {  // read again, to say what is wrong with it
    const auto manifest = jobs::readManifest(folder);
    planned = jobs::readJobSheets(folder, manifest);
    // (An object: its sheets were listed from it.)
    if (manifest.contains("panels") && manifest["panels"].is_array()) summary["panels"] = manifest["panels"].size();
    if (manifest.contains("cost")) summary["cost"] = manifest["cost"];
  }
  jobs::checkSheetsFitBed(planned, machine, unit);
  summary["sheets"] = static_cast<int>(planned.size());
  // (The sheets' own size: a folder made for a smaller bed is cut on sheets of its size.)
  addStock(machine, cuttingMaterial(folder, material),
           planned.empty() ? machine.bed.width : planned.front().drawing.width,
           planned.empty() ? machine.bed.height : planned.front().drawing.height, unit, summary);
  return summary;
}

void Service::Impl::planOnSubmission(NewJob& job, const fs::path& folder, const fs::path& submitted) {
  std::string why;
  // A folder made for a machine is cut on a device of that machine.
  std::optional<std::string> madeFor;
  try {
    madeFor = jobs::jobProfileNames(folder).machine;
  } catch (const std::exception&) {
    // (An unreadable manifest: its plan says what is wrong.)
  }
  const std::optional<Target> device = deviceFor(job.device, job.options, why, madeFor.value_or(""));
  if (!device) throw ApiError(409, inSubmittersWords(why, folder, submitted));
  json summary;
  try {
    summary = planOfFolder(folder, device->machine, device->material);
  } catch (const core::UserError& error) {
    throw ApiError(400, inSubmittersWords(error.what(), folder, submitted));
  } catch (const profiles::ProfileError& error) {
    // A material its manifest names that no profile here has.
    throw ApiError(400, inSubmittersWords(error.what(), folder, submitted));
  }
  const int sheets = summary["sheets"].get<int>();
  job.change.device = device->name;
  job.change.sheets = sheets;
  job.change.summary = summary.dump();
  job.then = {{JobState::Planning, [reason = planningReason(*device)](JobId) { return reason; }},
              {JobState::Ready, [sheets](JobId) { return plannedReason(sheets); }}};
}

void Service::Impl::startPlanning(const JobRecord& job, const Target& device) {
  jobChanged(job);
  auto cancel = std::make_shared<core::Cancellation>();
  // A plan that takes longer than plan_timeout is stopped, and its job fails saying so.
  auto timeout = std::make_shared<asio::steady_timer>(strand, std::chrono::duration_cast<asio::steady_timer::duration>(
                                                                  std::chrono::duration<double>(config.planTimeout)));
  timeout->async_wait([this, id = job.id](const boost::system::error_code& error) {
    if (error || stopping) return;  // the plan ended first, or the daemon's stop stops it
    if (auto p = planning.find(id); p != planning.end() && p->second.cancelledBy.empty()) {
      p->second.timedOut = true;
      p->second.cancel->cancel();
    }
  });
  planning[job.id] = Planning{cancel, json(), "", timeout, false, ""};
  {
    std::lock_guard lock(heldMutex);
    heldPlans[job.id] = cancel;
  }
  asio::post(planners, [this, job, machine = device.machine, material = device.material, cancel] {
    plan(job, machine, material, cancel);
  });
}

void Service::Impl::plan(const JobRecord& job, const profiles::MachineProfile& machine,
                         const profiles::MaterialProfile& material, const std::shared_ptr<core::Cancellation>& cancel) {
  const fs::path folder = spool->pathOf(job.spool);
  int sheets = 0;
  json summary;
  std::optional<std::string> failure;
  bool cancelled = false;
  std::string plannedName;
  try {
    if (job.kind == JobKind::Planned) {
      summary = planOfFolder(folder, machine, material);
      sheets = summary["sheets"].get<int>();
    } else {
      std::optional<jobs::MakeOptions> stored = storedOptions(job.options);
      if (!stored) throw ApiError(400, kNoStructure);
      jobs::MakeOptions& options = *stored;
      options.mesh = (folder / job.source).string();
      const bool machineGiven = options.given.contains("machine");
      const bool materialGiven = options.given.contains("material");
      if (machineGiven && options.machine != machine.name) {
        throw ApiError(400, fmt::format("--machine {}: device {} is a {}", options.machine, job.device, machine.name));
      }
      options.machine = machine.name;
      if (!materialGiven) options.material = material.name;
      // --units, else the daemon's (else requestOf() takes --size's unit, else the machine's).
      if (options.units.empty() && config.units) options.units = std::string(config.units->name());
      jobs::MakeRequest request = jobs::requestOf(options, catalogue);
      // The daemon cuts from the SVG: it is written whatever --formats says.
      request.formats = request.formats.value_or(jobs::defaultFormats(machine));
      request.formats->svg = true;
      const JobId id = job.id;
      auto last = std::make_shared<Clock::time_point>();
      auto said = std::make_shared<JobNotesSink::Said>();
      const core::WorkContext context(
          *executor, *cancel,
          [this, id, last](const core::Progress& progress) {
            const auto now = Clock::now();
            if (now - *last < std::chrono::milliseconds(250) && progress.total != progress.done) return;
            *last = now;
            json data{{"job", id},
                      {"phase", progress.phase},
                      {"step", progress.step},
                      {"done", progress.done},
                      {"total", progress.total}};
            if (progress.sheets > 0) data["layout_sheets"] = progress.sheets;
            onStrand([this, id, data] {
              if (auto p = planning.find(id); p != planning.end()) p->second.progress = data;
              publish("progress", data);
            });
          },
          std::make_shared<spdlog::logger>(
              "plan", std::make_shared<JobNotesSink>(log, folder, fmt::format("job {}", job.id), said)));
      plannedName = store->shared() ? fmt::format("planned-{}-{}", config.host, Clock::now().time_since_epoch().count())
                                    : "planned";
      jobs::PlannedJob planned = jobs::makeJob(request, folder / plannedName, context);
      syncFolder(folder / plannedName);
      syncFolder(folder);
      sheets = static_cast<int>(planned.files.size());
      summary = jobs::summaryJson(planned);
      summary.erase("stability");  // manifest.json has it; the queue shows what a cut needs
      summary["cost"] = jobs::costJson(planned.cost);
      summary["folder"] = plannedName;
      addStock(machine, request.material, machine.bed.width, machine.bed.height, request.shownIn, summary);
      if (const auto listed = jobs::readManifestSheets(folder / plannedName / "manifest.json"))
        addKits(*listed, summary);
      // What the plan said on the way, for the people at the machine (the page shows them).
      summary["notes"] = said->notes;
      summary["warnings"] = said->warnings;
    }
  } catch (const core::Cancelled&) {
    cancelled = true;
  } catch (const std::exception& error) {
    failure = inSubmittersWords(error.what(), folder);
    if (saysDiskFull(error.what())) {
      // What the plan wrote goes, so that its room is the disk's again.
      std::error_code ignored;
      if (!plannedName.empty()) fs::remove_all(folder / plannedName, ignored);
      failure = fmt::format(
          "the disk is full: its plan could not be written ({}); free some space, then submit it "
          "again",
          *failure);
    }
  }
  onStrand([this, id = job.id, sheets, summary, failure, cancelled] {
    std::string by, stoppedBecause;
    bool timedOut = false;
    if (auto p = planning.find(id); p != planning.end()) {
      by = p->second.cancelledBy;
      stoppedBecause = p->second.stoppedBecause;
      timedOut = p->second.timedOut;
      p->second.timeout->cancel();
      planning.erase(p);
    }
    {
      std::lock_guard lock(heldMutex);
      heldPlans.erase(id);
    }
    try {
      // (Whoever cancelled first says why: a person, the daemon's stop, or the timeout.)
      if (cancelled && timedOut && by.empty()) {
        const std::string why = fmt::format(
            "planning took longer than plan_timeout ({:g} s) and was stopped: give `make` a shorter --time, "
            "or raise plan_timeout in the daemon's configuration",
            config.planTimeout);
        log->warn("job {}: {}", id, why);
        jobChanged(record(id, JobState::Failed, why, {}, true));
      } else if (cancelled && by.empty() && !stoppedBecause.empty()) {
        jobChanged(record(
            id, JobState::Queued,
            fmt::format("{}: its plan was stopped; it is planned again once there is room", stoppedBecause), {}, true));
      } else if (cancelled && by.empty()) {
        record(id, JobState::Queued, "the daemon stopped while it planned; it is planned again", {}, true);
      } else if (cancelled) {
        jobChanged(record(id, JobState::Cancelled, fmt::format("cancelled while planning by {}", by), {}, true));
      } else if (failure) {
        log->warn("job {}: {}", id, *failure);
        jobChanged(record(id, JobState::Failed, *failure, {}, true));
      } else {
        JobChange change;
        change.sheets = sheets;
        change.summary = summary.dump();
        const JobRecord ready = record(id, JobState::Ready, plannedReason(sheets), change, true);
        log->info("job {}: planned, {} sheets", id, sheets);
        jobChanged(ready);
      }
    } catch (const std::exception& error) {
      log->error("job {}: {}", id, error.what());
    }
    finishIfStopping();
    pump();
  });
}

}  // namespace rotafab::service
