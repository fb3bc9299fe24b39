#include "daemon/service/Service.h"

#include <fmt/format.h>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <chrono>
#include <cmath>
#include <fstream>
#include <future>
#include <mutex>
#include <regex>
#include <set>
#include <thread>

#include "core/Executor.h"
#include "core/UserError.h"
#include "core/WorkContext.h"
#include "daemon/service/ApiInput.h"
#include "daemon/service/DiskReserve.h"
#include "daemon/service/UploadForm.h"
#include "devices/Device.h"
#include "devices/DriverEntry.h"
#include "devices/JobRun.h"
#include "geometry/PolygonMesh.h"
#include "profiles/Profiles.h"
#include "toolpath/JobSheets.h"
#include "toolpath/ManifestFile.h"
#include "toolpath/Toolpath.h"

namespace rotafab::service {
namespace asio = boost::asio;
namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

// A sheet's toolpath for people (docs/API.md, GET /api/jobs/ID/sheets/N): every
// stroke in the order the laser burns it, so that the stroke a cut's
// progress counts is the stroke at that index; to a thousandth of an inch.
json toolpathJson(const jobs::Toolpath& path) {
  const auto rounded = [](double value) { return std::round(value * 1000) / 1000; };
  json strokes = json::array();
  for (const jobs::ToolpathStroke& stroke : path.strokes) {
    json points = json::array();
    for (const auto& point : stroke.points) points.push_back({rounded(point.x()), rounded(point.y())});
    strokes.push_back({{"operation", profiles::operationName(stroke.operation)},
                       {"pass", stroke.pass},
                       {"power", rounded(stroke.power)},
                       {"points", std::move(points)}});
  }
  return {{"sheet", path.sheet},
          {"width", path.width},
          {"height", path.height},
          {"seconds", std::round(path.seconds * 10) / 10},
          {"burn_length", rounded(path.burnLength)},
          {"travel_length", rounded(path.travelLength)},
          {"strokes", std::move(strokes)}};
}

std::string isoTime(double unixSeconds) {
  const auto seconds = static_cast<std::time_t>(unixSeconds);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

// A mesh submitted without options: as `rotafab make` says it.
constexpr const char* kNoStructure = "make options: --structure is required";

// A job's `make` options as the store keeps them (an object of options; a
// list of words in stores written before), read by make's table.
std::optional<jobs::MakeOptions> storedOptions(const std::string& stored) {
  if (stored.empty()) return std::nullopt;
  return makeOptionsOf(json::parse(stored, nullptr, false));
}

// A message about a file in the spool, in the words of the file the
// submitter named: the spool's folder dropped, or said as `submitted`.
std::string inSubmittersWords(std::string message, const fs::path& folder, const fs::path& submitted = {}) {
  const std::string prefix = folder.string() + "/";
  const std::string as = submitted.empty() ? "" : (submitted / "").string();
  for (size_t at = message.find(prefix); at != std::string::npos; at = message.find(prefix, at + as.size())) {
    message.replace(at, prefix.size(), as);
  }
  return message;
}

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

std::string sheetWhere(int sheet, int sheets, int64_t stroke, int64_t strokes) {
  if (sheet <= 0) return "before the first sheet";
  return fmt::format("at sheet {} of {}, after stroke {} of {}", sheet, sheets, stroke, strokes);
}

}  // namespace

// Between a running job's driver thread and the strand.
struct RunControl {
  core::Cancellation cancel;
  std::atomic<bool> shutdown{false};
  std::atomic<devices::JobRun*> run{nullptr};
};

struct Service::Impl {
  struct Device {
    DeviceConfig config;
    profiles::MachineProfile machine;
    profiles::MaterialProfile material;
    std::string state = "checking";  // checking, idle, running, paused, offline, fault
    std::string message;
    std::string checked;  // what the check at the daemon's start found
    std::optional<JobId> job;
  };
  // A device a job may be planned for or cut on: this host's, or another's
  // on a shared store (its profiles from this host's catalogue, by the
  // names its own host gave).
  struct Target {
    std::string name, host;
    profiles::MachineProfile machine;
    profiles::MaterialProfile material;
  };
  struct Planning {
    std::shared_ptr<core::Cancellation> cancel;
    json progress;
    std::string cancelledBy;  // who asked; empty: the daemon stopping
    std::shared_ptr<asio::steady_timer> timeout;
    bool timedOut = false;
    std::string stoppedBecause;  // stopped by the daemon for this (a full disk): queued to be planned again
  };
  struct Cut {
    std::shared_ptr<RunControl> control;
    std::thread thread;
    size_t device = 0;
    int firstSheet = 1;
    json progress;
    std::optional<std::promise<bool>> waiting;  // set while the job waits for `next`
    std::string cancelledBy;
    std::string stoppedBecause;  // stopped by the daemon for this (a full disk): interrupted
    Clock::time_point lastStored{}, lastSent{};
  };

  Impl(asio::io_context& io, const DaemonConfig& config, std::shared_ptr<spdlog::logger> log)
      : io(io),
        config(config),
        log(std::move(log)),
        planners(config.planners),
        executor(std::make_unique<core::Executor>(std::max(1u, std::thread::hardware_concurrency()))) {}

  asio::io_context& io;
  const DaemonConfig& config;
  std::shared_ptr<spdlog::logger> log;
  asio::thread_pool state{1};
  asio::strand<asio::thread_pool::executor_type> strand{state.get_executor()};
  asio::thread_pool workers{2};
  asio::thread_pool planners;
  std::unique_ptr<core::Executor> executor;
  std::unique_ptr<JobStore> store;
  std::unique_ptr<Spool> spool;
  profiles::ProfileCatalogue catalogue;
  std::vector<Device> devices;
  std::map<JobId, Planning> planning;
  std::map<JobId, std::unique_ptr<Cut>> cuts;
  std::vector<std::thread> checks;
  std::map<size_t, std::function<void(const ServiceEvent&)>> subscribers;
  // Submissions whose files are written: synced together (on syncStrand),
  // then added together (on the strand), so that the clients who submit at
  // once share one syncfs and one transaction.
  struct Pending {
    Spool::Entry entry;
    NewJob job;
    ReplyHandler done;
  };
  // Its own thread: a sync never waits behind a submission's work (a large folder's sheets read).
  asio::thread_pool syncer{1};
  asio::strand<asio::thread_pool::executor_type> syncStrand{syncer.get_executor()};
  std::vector<std::shared_ptr<Pending>> toSync, toAdd;
  // Group commit: a group of entries is synced once no other submission is
  // still being written in the workers (or kGroupWait after its first entry,
  // so that a large upload does not hold the others back). Synced as each
  // came, the store's commits held 2.8 submissions on average; now about 5,
  // and a commit costs the daemon more CPU than the submission's own work
  // on the store. (A wait of 1 ms ended groups early: fewer per commit.)
  static constexpr auto kGroupWait = std::chrono::milliseconds(5);
  static constexpr size_t kLargestGroup = 256;
  std::atomic<int> beingWritten{0};  // submissions in the workers
  asio::steady_timer groupTimer{syncStrand};
  bool groupTimerSet = false;
  size_t nextSubscriber = 1;
  std::atomic<bool> stopping{false};
  // A full disk (DiskReserve.h): set once a write of the job store finds no
  // room (or the daemon starts without any), until the disk has room again.
  // Meanwhile nothing new is taken on, and what ends is recorded with the
  // reserve's room; a transition that even that cannot record is kept here
  // (the API shows it) and written once it can be.
  std::optional<DiskReserve> reserve;
  std::atomic<bool> diskFull{false};
  asio::steady_timer diskTimer{strand};
  struct Unrecorded {
    JobState to;
    std::string reason;
    JobChange change;
  };
  std::map<JobId, std::vector<Unrecorded>> unrecorded;
  // On a shared store: whether this host is in it (joined, lease renewed),
  // when its lease was last renewed, and the timer that renews it and
  // looks for work other hosts added.
  bool joined = false;
  Clock::time_point lastBeat{};  // when the last heartbeat that renewed the lease was sent
  std::optional<asio::steady_timer> ticker;
  // The lease watchdog, off the strand: a strand held up in a call to the
  // store (a network gone silent) must not keep a laser cutting a job that
  // another host may release. Until `safeUntil` (steady clock, ns; 4/5 of
  // the lease after the last renewal was sent) this host's lease surely
  // holds; past it, every cut and plan is stopped at once from here.
  std::thread watchdog;
  std::atomic<bool> watching{false}, leaseLost{false};
  std::atomic<int64_t> safeUntil{INT64_MAX};
  std::mutex heldMutex;  // the cuts' and plans' cancels, for the watchdog
  std::map<JobId, std::shared_ptr<RunControl>> heldCuts;
  std::map<JobId, std::shared_ptr<core::Cancellation>> heldPlans;

  void leaseRenewed(Clock::time_point sent) {
    lastBeat = sent;
    const auto margin = std::chrono::duration<double>(config.lease * 0.8);
    safeUntil = std::chrono::duration_cast<std::chrono::nanoseconds>(
                    (sent + std::chrono::duration_cast<Clock::duration>(margin)).time_since_epoch())
                    .count();
  }

  void watchLease() {
    while (watching) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
      if (now <= safeUntil || leaseLost.exchange(true)) continue;
      std::lock_guard lock(heldMutex);
      log->error("host {}: its lease on the job store was not renewed in time: stopping its {} cut{} and {} plan{}",
                 config.host, heldCuts.size(), heldCuts.size() == 1 ? "" : "s", heldPlans.size(),
                 heldPlans.size() == 1 ? "" : "s");
      for (auto& [id, control] : heldCuts) {
        control->shutdown = true;
        control->cancel.cancel();
      }
      for (auto& [id, cancel] : heldPlans) cancel->cancel();
      onStrand([this] { fence("its lease was not renewed in time"); });
    }
  }
  // The devices of the other live hosts, as the last heartbeat found them;
  // read off the strand too (a planned folder's submission), hence the lock.
  std::mutex othersMutex;
  std::vector<Target> others;
  std::function<void()> stopped;

  template <typename Work>
  void onStrand(Work&& work) {
    asio::post(strand, std::forward<Work>(work));
  }

  // Runs `work` on the strand and replies with what it returns, or the error it throws.
  void answer(ReplyHandler done, std::function<Reply()> work) {
    onStrand([this, done = std::move(done), work = std::move(work)] { done(guarded(work)); });
  }

  Reply guarded(const std::function<Reply()>& work) {
    try {
      return work();
    } catch (const ApiError& error) {
      json body = error.details.is_object() ? error.details : json::object();
      body["error"] = error.what();
      return {error.status, body};
    } catch (const TransitionRefused& error) {
      return {409, {{"error", error.what()}}};
    } catch (const StoreError& error) {
      log->error("{}", error.what());
      return {507, {{"error", error.what()}}};
    } catch (const std::exception& error) {
      log->error("{}", error.what());
      return {500, {{"error", error.what()}}};
    }
  }

  void publish(const std::string& type, json data) {
    const ServiceEvent event{type, std::move(data)};
    for (const auto& [id, sink] : subscribers) sink(event);
  }

  Device* deviceNamed(const std::string& name) {
    for (Device& device : devices) {
      if (device.config.name == name) return &device;
    }
    return nullptr;
  }

  std::string deviceNames() const {
    std::string names;
    for (const Device& device : devices) names += (names.empty() ? "" : ", ") + device.config.name;
    return names;
  }

  JobRecord jobOrThrow(JobId id) {
    auto job = store->job(id);
    if (!job) throw ApiError(404, fmt::format("there is no job {}", id));
    return *job;
  }

  fs::path plannedFolder(const JobRecord& job) const {
    const fs::path folder = spool->pathOf(job.spool);
    if (job.kind == JobKind::Planned) return folder;
    // On a shared store each plan has a folder of its own, named in its
    // summary: a plan a stalled host finishes late never overwrites the one
    // made since by another host.
    const json summary = json::parse(job.summary.empty() ? "{}" : job.summary, nullptr, false);
    if (summary.is_object() && summary.contains("folder") && summary["folder"].is_string()) {
      const std::string name = summary["folder"];
      if (name.starts_with("planned") && name.find('/') == std::string::npos) return folder / name;
    }
    return folder / "planned";
  }

  json deviceJson(const Device& device) const {
    json out{{"name", device.config.name},
             {"host", config.host},
             {"uri", device.config.uri},
             {"machine", device.machine.name},
             {"material", device.material.name},
             {"auto_start", device.config.autoStart},
             {"state", device.state}};
    if (!device.message.empty()) out["message"] = device.message;
    if (!device.checked.empty()) out["checked"] = device.checked;
    out["job"] = device.job ? json(*device.job) : json(nullptr);
    return out;
  }

  // The job as the store has it, with the transitions a full disk kept from being recorded.
  JobRecord withUnrecorded(JobRecord job) const {
    const auto found = unrecorded.find(job.id);
    if (found == unrecorded.end()) return job;
    for (const Unrecorded& change : found->second) {
      job.state = change.to;
      job.message = change.reason + " (not yet recorded: the disk is full)";
      if (change.change.device) job.device = *change.change.device;
      if (change.change.summary) job.summary = *change.change.summary;
      if (change.change.sheets) job.sheets = *change.change.sheets;
      if (change.change.sheet) job.sheet = *change.change.sheet;
      if (change.change.stroke) job.stroke = *change.change.stroke;
      if (change.change.strokes) job.strokes = *change.change.strokes;
    }
    return job;
  }

  json jobJson(const JobRecord& stored) const {
    const JobRecord job = withUnrecorded(stored);
    json out{{"id", job.id},
             {"state", stateName(job.state)},
             {"kind", kindName(job.kind)},
             {"source", job.source},
             {"owner", job.owner},
             {"device", job.device.empty() ? json(nullptr) : json(job.device)},
             {"priority", job.priority},
             {"submitted", isoTime(job.submitted)},
             {"updated", isoTime(job.updated)},
             {"sheets", job.sheets},
             {"sheet", job.sheet},
             {"stroke", job.stroke},
             {"strokes", job.strokes},
             {"message", job.message}};
    out["host"] = job.host.empty() ? json(nullptr) : json(job.host);
    // (As the words of `rotafab make`, as the API has always shown them.)
    try {
      const auto options = storedOptions(job.options);
      out["options"] = options ? json(jobs::optionWords(*options)) : json::array();
    } catch (const ApiError&) {
      out["options"] = json::parse(job.options, nullptr, false);
    }
    if (!job.summary.empty()) out["summary"] = json::parse(job.summary, nullptr, false);
    if (const auto p = planning.find(job.id); p != planning.end() && !p->second.progress.is_null()) {
      out["progress"] = p->second.progress;
    }
    if (const auto c = cuts.find(job.id); c != cuts.end()) {
      if (!c->second->progress.is_null()) out["progress"] = c->second->progress;
      out["waiting_for_next"] = c->second->waiting.has_value();
    }
    return out;
  }

  void jobChanged(const JobRecord& job) {
    if (!subscribers.empty()) publish("job", jobJson(job));
  }

  void deviceChanged(const Device& device) {
    try {
      store->putDevice(deviceRecord(device));
    } catch (const std::exception& error) {
      storeTrouble(fmt::format("device {}", device.config.name), error);
    }
    publish("device", deviceJson(device));
  }

  // ---- a full disk ----

  static constexpr std::string_view kDiskFull = "the disk that holds the daemon's state is full";

  std::string diskFullRefusal() const {
    return fmt::format(
        "{}: nothing new is taken on until there is room again (free some space on it; the daemon "
        "goes on by itself)",
        kDiskFull);
  }

  // A write to the store failed: a full disk is a state of its own
  // (diskBecameFull); anything else is logged.
  void storeTrouble(const std::string& what, const std::exception& error) {
    if (saysDiskFull(error.what())) return diskBecameFull(error.what());
    log->error("{}: {}", what, error.what());
  }

  // A cut this daemon stops by itself, for `because` (empty: its stop): laser off, left interrupted.
  static void stopCutByItself(Cut& cut, const std::string& because) {
    if (cut.stoppedBecause.empty()) cut.stoppedBecause = because;
    cut.control->shutdown = true;
    cut.control->cancel.cancel();
    if (cut.waiting) {
      cut.waiting->set_value(false);
      cut.waiting.reset();
    }
  }

  // A write of the store found no room: the reserve's room is given back
  // (so that what ends now can be recorded), every cut stops with its laser
  // off and is left interrupted (its progress could no longer be kept),
  // every plan stops and is queued again, and nothing new is taken on until
  // the disk has room again (watchDisk). Said once in the log, not at every write.
  void diskBecameFull(const std::string& why) {
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

  // While the disk is full: every 2 s, what was kept from the store is
  // written if it can be, and once the disk has room for the reserve and as
  // much again, the reserve is made again and the queue goes on.
  void watchDisk() {
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

  // A transition the store must record; on a full disk, with the reserve's
  // room. With `keepIfFull` (the end of a cut or a plan, which has happened
  // whatever the disk says) one that even that cannot record is kept in
  // `unrecorded`, shown as done, and written once it can be; otherwise the
  // StoreError goes to the caller (an operator's action is refused, 507).
  JobRecord record(JobId id, JobState to, const std::string& reason, const JobChange& change = {},
                   bool keepIfFull = false) {
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

  void writeUnrecorded() {
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

  // ---- start ----

  void open() {
    std::error_code error;
    fs::create_directories(config.stateDir, error);
    if (error) {
      throw StoreError(
          fmt::format("{}: cannot create the state directory: {}", config.stateDir.string(), error.message()));
    }
    // Before the store is opened (its start writes), room for what must be written.
    reserve.emplace(config.stateDir / "rotafabd.reserve");
    if (!reserve->enough() || !reserve->hold()) {
      reserve->release();
      diskFull = true;
      log->error(
          "{}: the daemon starts to answer and to cancel, with what room there is; nothing new is taken on "
          "until there is room again",
          kDiskFull);
    }
    store = config.store.empty() ? openSqliteStore(config.stateDir / "jobs.sqlite3") : openPostgresStore(config.store);
    spool = std::make_unique<Spool>(config.spool.empty() ? config.stateDir / "spool" : config.spool,
                                    store->shared() ? config.host : "");
    catalogue = profiles::loadProfiles(profiles::profileSearchPath());
    const std::string where = config.file.empty() ? std::string("the default configuration") : config.file.string();
    for (const DeviceConfig& deviceConfig : config.devices) {
      Device device;
      device.config = deviceConfig;
      devices::ParsedUri uri;
      try {
        uri = devices::parseDeviceUri(deviceConfig.uri);
      } catch (const std::invalid_argument& bad) {
        throw ConfigError(fmt::format("{}: device {}: {}", where, deviceConfig.name, bad.what()));
      }
      try {
        if (deviceConfig.machine.empty()) {
          const auto machine = profiles::firstMachineFor(catalogue, uri.driver->name());
          if (!machine) {
            throw ConfigError(fmt::format("{}: device {}: no machine profile for the {} driver; give machine:", where,
                                          deviceConfig.name, uri.driver->name()));
          }
          device.machine = *machine;
        } else {
          device.machine = profiles::findMachine(catalogue, deviceConfig.machine);
        }
        device.material = profiles::findMaterial(catalogue, deviceConfig.material);
      } catch (const profiles::ProfileError& bad) {
        throw ConfigError(fmt::format("{}: device {}: {}", where, deviceConfig.name, bad.what()));
      }
      if (device.machine.driver != uri.driver->name()) {
        throw ConfigError(fmt::format("{}: device {}: machine {} is driven by {}, not by {}'s {} driver", where,
                                      deviceConfig.name, device.machine.name, device.machine.driver, deviceConfig.uri,
                                      uri.driver->name()));
      }
      devices.push_back(std::move(device));
    }
  }

  // What becomes of a job whose host stopped: cut, it is interrupted (never
  // restarted by itself); planned, it is planned again. `who`: "the daemon"
  // after this host's own stop, else the host whose lease ran out.
  static std::pair<JobState, std::string> released(const JobRecord& job, const std::string& who) {
    if (holdsDevice(job.state)) {
      return {
          JobState::Interrupted,
          fmt::format("{} stopped while it cut, {}; check the machine and the sheet, then go on with `rotafab "
                      "resume {} --from-sheet {}`",
                      who, sheetWhere(job.sheet, job.sheets, job.stroke, job.strokes), job.id, std::max(1, job.sheet))};
    }
    return {JobState::Queued, fmt::format("{} stopped while it planned; it is planned again", who)};
  }

  DeviceRecord deviceRecord(const Device& device) const {
    DeviceRecord record;
    record.name = device.config.name;
    record.host = config.host;
    record.machine = device.machine.name;
    record.material = device.material.name;
    record.uri = device.config.uri;
    record.autoStart = device.config.autoStart;
    record.state = device.state;
    record.message = device.message;
    record.job = device.job;
    return record;
  }

  // This host into the store (again, after its lease ran out), and what it
  // held before released: jobs it was cutting become interrupted, plans it
  // was making are made again. `wait`: seconds to wait for a lease this
  // host's name still holds (a daemon killed a moment ago holds it a little longer).
  void joinStore(double wait) {
    HostRecord me;
    me.name = config.host;
    for (const std::string& address : config.listen) {
      if (address.starts_with("tcp://")) {
        me.address = "http://" + address.substr(6);
        break;
      }
    }
    std::vector<DeviceRecord> records;
    for (const Device& device : devices) records.push_back(deviceRecord(device));
    const auto sent = Clock::now();
    const std::vector<JobRecord> left =
        store->join(me, records, config.lease, wait,
                    [](const JobRecord& job, const HostRecord&) { return released(job, "the daemon"); });
    joined = true;
    if (store->shared()) {
      leaseRenewed(sent);
      leaseLost = false;
    }
    for (const JobRecord& job : left) {
      if (job.state == JobState::Interrupted) log->warn("job {}: {}", job.id, job.message);
      jobChanged(job);
    }
    if (store->shared()) refreshOthers();
  }

  // At the start: into the store; spool folders no job names (a stop
  // mid-submission) removed; on a shared store, the heartbeat started.
  void join() {
    joinStore(config.lease + 2);
    std::set<std::string> named;
    store->eachJob([&](const JobRecord& job) { named.insert(job.spool); });
    if (const size_t removed = spool->removeOrphans(named); removed > 0) {
      log->info("removed {} spool folder{} that no job names (left by a stop mid-submission)", removed,
                removed == 1 ? "" : "s");
    }
    if (store->shared()) {
      log->info("host {} on the shared job store, lease {:g} s", config.host, config.lease);
      ticker.emplace(strand);
      tick();
      watching = true;
      watchdog = std::thread([this] { watchLease(); });
    }
  }

  // On a shared store, twice a second: work the other hosts added; five
  // times a lease, the heartbeat, and the hosts whose lease ran out.
  void tick() {
    ticker->expires_after(std::chrono::milliseconds(500));
    ticker->async_wait([this](const boost::system::error_code& error) {
      if (error) return;
      // The heartbeat first, by the clock; and on until a stop has stopped every cut.
      if (Clock::now() - lastBeat >= std::chrono::duration<double>(config.lease / 5)) beat();
      if (stopping) {
        if (!cuts.empty() || !planning.empty()) tick();
        return;
      }
      if (joined && !leaseLost) {
        try {
          serveRequests();
        } catch (const std::exception& failure) {
          log->error("{}", failure.what());
        }
      }
      pump();
      tick();
    });
  }

  void beat() {
    try {
      if (!joined) {
        // Again, after its lease ran out, once every cut and plan it had has
        // stopped; without waiting (a refusal is tried again at the next beat).
        if (stopping || !cuts.empty() || !planning.empty()) return;
        joinStore(0);
        log->info("host {} joined the shared job store again", config.host);
        return;
      }
      const auto sent = Clock::now();
      if (!store->heartbeat(config.lease)) {
        fence("its lease ran out and another host released its jobs");
        return;
      }
      leaseRenewed(sent);
      const std::vector<JobRecord> taken = store->releaseLapsedHosts([](const JobRecord& job, const HostRecord& host) {
        return released(job, fmt::format("host {} (its last heartbeat {})", host.name, isoTime(host.seen)));
      });
      for (const JobRecord& job : taken) {
        log->warn("job {}: {}", job.id, job.message);
        jobChanged(job);
      }
      refreshOthers();
    } catch (const std::exception& error) {
      log->error("{}", error.what());  // (the watchdog stops the cuts if the lease is not renewed in time)
    }
  }

  // This host's lease ran out (it was stalled, or cut off from the store):
  // another host may take its jobs, so it stops them at once, lasers off,
  // and joins the store again (which releases what it still held).
  void fence(const std::string& why) {
    if (!joined) return;
    log->error("host {}: {}: stopping its cuts and plans", config.host, why);
    joined = false;
    leaseLost = true;
    for (auto& [id, plan] : planning) plan.cancel->cancel();
    for (auto& [id, cut] : cuts) stopCutByItself(*cut, "");
  }

  // The actions other hosts left for this host's jobs, done as if asked here.
  void serveRequests() {
    for (const ActionRequest& request : store->takeRequests()) {
      const json arguments = json::parse(request.arguments, nullptr, false);
      // (Checked again here: the store is an edge too, for what another host's daemon left in it.)
      const Reply reply = guarded([&] {
        return act(request.job, request.action,
                   checkedActionArguments(request.action, arguments.is_discarded() ? json::object() : arguments),
                   request.who);
      });
      if (reply.status >= 400) {
        const std::string why = reply.body.value("error", "refused");
        log->warn("job {}: {}'s {} through another host: {}", request.job, request.who, request.action, why);
        store->addEvent(request.job, "refused", fmt::format("{}'s {}: {}", request.who, request.action, why));
      }
    }
  }

  void refreshOthers() {
    std::vector<Target> found;
    for (const DeviceRecord& device : store->devices()) {
      if (device.host == config.host || device.state == "gone") continue;
      try {
        found.push_back({device.name, device.host, profiles::findMachine(catalogue, device.machine),
                         profiles::findMaterial(catalogue, device.material)});
      } catch (const profiles::ProfileError&) {
        // A profile this host does not have: it cannot plan for that device.
      }
    }
    std::lock_guard lock(othersMutex);
    others = std::move(found);
  }

  // " (http://HOST:PORT)" where another host's API answers, when it said.
  std::string hostAddressSaid(const std::string& host) {
    try {
      for (const HostRecord& record : store->hosts()) {
        if (record.name == host && !record.address.empty()) return " (" + record.address + ")";
      }
    } catch (const std::exception&) {
    }
    return "";
  }

  // Every device is stopped safely before anything is cut: whatever a run
  // before this daemon left behind (a kill -9 mid-cut leaves a real GRBL
  // burning through what it had buffered), its laser is off.
  void checkDevices() {
    for (size_t index = 0; index < devices.size(); ++index) {
      const std::string uri = devices[index].config.uri;
      const profiles::MachineProfile machine = devices[index].machine;
      checks.emplace_back([this, index, uri, machine] {
        std::string state = "idle", message;
        try {
          devices::ParsedUri parsed = devices::parseDeviceUri(uri);
          devices::DeviceSetup setup;
          for (profiles::Operation operation : profiles::kAllOperations) {
            setup.colours[operation] = machine.settingFor(operation).rgb;
          }
          auto device = parsed.driver->open(*parsed.address, setup);
          const std::string identity = device->connect();
          const bool off = device->stopSafely();
          device->disconnect();
          message = off ? fmt::format("{}; stopped, laser off confirmed", identity)
                        : fmt::format("{}; stopped, but the controller did not confirm its laser off", identity);
        } catch (const devices::DeviceFault& fault) {
          state = "offline";
          message = fault.what();
        } catch (const std::exception& error) {
          state = "offline";
          message = error.what();
        }
        onStrand([this, index, state, message] {
          Device& device = devices[index];
          if (device.state == "checking") device.state = state;
          if (state == "offline") device.message = message;
          device.checked = message;
          if (state == "offline") {
            log->warn("device {}: offline: {}", device.config.name, message);
          } else {
            log->info("device {}: {}", device.config.name, message);
          }
          store->addEvent(std::nullopt, "device", fmt::format("{}: {}: {}", device.config.name, state, message));
          deviceChanged(device);
          pump();
        });
      });
    }
  }

  // ---- the queue ----

  // Starts what can start: plans for queued jobs while a planner is free,
  // and cuts of ready jobs on idle devices configured to start by themselves.
  // Each job is claimed from the store (JobStore::claim), so that on a
  // shared store no two hosts plan or cut the same one.
  void pump() {
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
                           if (job.sheets < 1) return std::nullopt;
                           return Claim{JobState::Running, reason, cutFromSheet(1, device.config.name)};
                         });
        for (const JobRecord& job : claimed) {
          try {
            launchCut(job, device, 1);
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

  static Target targetOf(const Device& device, const std::string& host) {
    return {device.config.name, host, device.machine, device.material};
  }

  // The device a job is planned against: the one it names, or the first
  // (this host's before the others') whose machine profile the job's
  // options do not rule out. It reads only what open() set and the other
  // hosts' devices under their lock, so a submission may ask it off the strand.
  std::optional<Target> deviceFor(const std::string& named, const std::string& options, std::string& why) {
    std::vector<Target> all;
    for (const Device& device : devices) all.push_back(targetOf(device, config.host));
    {
      std::lock_guard lock(othersMutex);
      all.insert(all.end(), others.begin(), others.end());
    }
    std::string names;
    for (const Target& target : all) names += (names.empty() ? "" : ", ") + target.name;
    if (!named.empty()) {
      for (const Target& target : all) {
        if (target.name == named) return target;
      }
      why = fmt::format("there is no device {} (the devices: {})", named, names);
      return std::nullopt;
    }
    if (all.empty()) {
      why = "the daemon has no devices";
      return std::nullopt;
    }
    std::string machine;
    try {
      if (const auto given = storedOptions(options); given && given->given.contains("machine")) {
        machine = given->machine;
      }
    } catch (const ApiError&) {
      // (Its plan says what is wrong with them.)
    }
    for (const Target& target : all) {
      if (machine.empty() || target.machine.name == machine) return target;
    }
    why = fmt::format("no device has the machine profile {} (the devices: {})", machine, names);
    return std::nullopt;
  }

  static std::string planningReason(const Target& device) {
    return fmt::format("planning against {} ({})", device.name, device.machine.name);
  }

  static std::string plannedReason(int sheets, JobId id) {
    return fmt::format("planned: {} sheet{}; start it with `rotafab start {}`", sheets, sheets == 1 ? "" : "s", id);
  }

  // A planned folder's plan: its sheets read and checked against the bed
  // they are to be cut on; the summary the queue shows, from its manifest.
  static json planOfFolder(const fs::path& folder, const profiles::MachineProfile& machine) {
    json summary;
    std::vector<jobs::JobSheet> planned;
    if (const auto listed = jobs::readManifestSheets(folder / "manifest.json")) {
      planned = jobs::readJobSheets(folder, listed->svgSheets);
      if (listed->panels) summary["panels"] = *listed->panels;
      if (listed->cost) summary["cost"] = json::parse(*listed->cost);
    } else {  // read again, to say what is wrong with it
      const auto manifest = jobs::readManifest(folder);
      planned = jobs::readJobSheets(folder, manifest);
      // (An object: its sheets were listed from it.)
      if (manifest.contains("panels") && manifest["panels"].is_array()) summary["panels"] = manifest["panels"].size();
      if (manifest.contains("cost")) summary["cost"] = manifest["cost"];
    }
    jobs::checkSheetsFitBed(planned, machine);
    summary["sheets"] = static_cast<int>(planned.size());
    return summary;
  }

  // A planned folder is planned while it is submitted (off the strand, in
  // the submission's worker): its job is added ready, its queued, planning
  // and ready recorded in the one transaction that adds it, where planning
  // it from the queue would cost two more synced commits. A folder whose
  // sheets are unreadable, or too large for the device's bed, is refused
  // then and there, in the words of the folder the submitter named.
  void planOnSubmission(NewJob& job, const fs::path& folder, const fs::path& submitted) {
    std::string why;
    const std::optional<Target> device = deviceFor(job.device, job.options, why);
    if (!device) throw ApiError(409, why);
    json summary;
    try {
      summary = planOfFolder(folder, device->machine);
    } catch (const core::UserError& error) {
      throw ApiError(400, inSubmittersWords(error.what(), folder, submitted));
    }
    const int sheets = summary["sheets"].get<int>();
    job.change.device = device->name;
    job.change.sheets = sheets;
    job.change.summary = summary.dump();
    job.then = {{JobState::Planning, [reason = planningReason(*device)](JobId) { return reason; }},
                {JobState::Ready, [sheets](JobId id) { return plannedReason(sheets, id); }}};
  }

  // A job this host claimed to plan (planning, its device set): planned on a planner.
  void startPlanning(const JobRecord& job, const Target& device) {
    jobChanged(job);
    auto cancel = std::make_shared<core::Cancellation>();
    // A plan that takes longer than plan_timeout is stopped, and its job fails saying so.
    auto timeout = std::make_shared<asio::steady_timer>(
        strand,
        std::chrono::duration_cast<asio::steady_timer::duration>(std::chrono::duration<double>(config.planTimeout)));
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

  // On a planner: the job's plan, against its device's profiles.
  void plan(const JobRecord& job, const profiles::MachineProfile& machine, const profiles::MaterialProfile& material,
            const std::shared_ptr<core::Cancellation>& cancel) {
    const fs::path folder = spool->pathOf(job.spool);
    int sheets = 0;
    json summary;
    std::optional<std::string> failure;
    bool cancelled = false;
    std::string plannedName;
    try {
      if (job.kind == JobKind::Planned) {
        summary = planOfFolder(folder, machine);
        sheets = summary["sheets"].get<int>();
      } else {
        std::optional<jobs::MakeOptions> stored = storedOptions(job.options);
        if (!stored) throw ApiError(400, kNoStructure);
        jobs::MakeOptions& options = *stored;
        options.mesh = (folder / job.source).string();
        const bool machineGiven = options.given.contains("machine");
        const bool materialGiven = options.given.contains("material");
        if (machineGiven && options.machine != machine.name) {
          throw ApiError(400,
                         fmt::format("--machine {}: device {} is a {}", options.machine, job.device, machine.name));
        }
        options.machine = machine.name;
        if (!materialGiven) options.material = material.name;
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
        plannedName = store->shared()
                          ? fmt::format("planned-{}-{}", config.host, Clock::now().time_since_epoch().count())
                          : "planned";
        jobs::PlannedJob planned = jobs::makeJob(request, folder / plannedName, context);
        syncFolder(folder / plannedName);
        syncFolder(folder);
        sheets = static_cast<int>(planned.files.size());
        summary = jobs::summaryJson(planned);
        summary.erase("stability");  // manifest.json has it; the queue shows what a cut needs
        summary["cost"] = jobs::costJson(planned.cost);
        summary["folder"] = plannedName;
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
          jobChanged(
              record(id, JobState::Queued,
                     fmt::format("{}: its plan was stopped; it is planned again once there is room", stoppedBecause),
                     {}, true));
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
          const JobRecord ready = record(id, JobState::Ready, plannedReason(sheets, id), change, true);
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

  // What a cut from `fromSheet` on `device` changes in its job.
  static JobChange cutFromSheet(int fromSheet, const std::string& device) {
    JobChange change;
    change.device = device;
    change.sheet = fromSheet;
    change.stroke = 0;
    change.strokes = 0;
    return change;
  }

  // The device of this host a job is cut on: its own, or, for a job
  // submitted for any device, one of this host's of the same machine.
  // Otherwise another host's device: the job is started there.
  Device& localDeviceFor(const JobRecord& job) {
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

  void startCut(const JobRecord& job, int fromSheet, const std::string& reason) {
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

  // A job this host moved to running on `device`: its cut on a thread of its own.
  void launchCut(const JobRecord& job, Device& on, int fromSheet) {
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

  // On the job's own thread: the driver's loop, its events posted to the strand.
  void runCut(JobId id, const std::shared_ptr<RunControl>& control, const std::string& uri,
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
      setup.material = material;
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

  void cutProgress(JobId id, const devices::Progress& progress, int sheet, int sheets) {
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

  void cutEnded(JobId id, const std::optional<devices::DeviceFault>& fault, const std::optional<std::string>& failure,
                const devices::RunSummary& summary) {
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
        ended = record(id, JobState::Done,
                       fmt::format("cut on {}: {} sheet{} from sheet {}, {} strokes, {:.1f} in burnt",
                                   device.config.name, summary.sheets, summary.sheets == 1 ? "" : "s", cut->firstSheet,
                                   summary.strokes, summary.burnt),
                       change, true);
      } else if (failure) {
        device.state = "fault";
        device.message = *failure;
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
        const int goOn = std::max(1, fault->sheet);
        if (fault->kind == devices::FaultKind::Cancelled && cut->control->shutdown) {
          const std::string stopped = cut->stoppedBecause.empty()
                                          ? std::string("the daemon stopped")
                                          : cut->stoppedBecause + ": the daemon stopped the cut";
          ended = record(
              id, JobState::Interrupted,
              fmt::format("{} {}; {}; go on with `rotafab resume {} --from-sheet {}`", stopped, where, laser, id, goOn),
              change, true);
        } else if (fault->kind == devices::FaultKind::Cancelled) {
          ended = record(id, JobState::Cancelled,
                         fmt::format("cancelled{} {}; {}", cut->cancelledBy.empty() ? "" : " by " + cut->cancelledBy,
                                     where, laser),
                         change, true);
        } else {
          device.state = "fault";
          device.message = fault->what();
          ended = record(
              id, JobState::Failed,
              fmt::format("{} ({}; stopped {}; {}); to go on once it is fixed: `rotafab resume {} --from-sheet {}`",
                          fault->what(), devices::faultName(fault->kind), where, laser, id, goOn),
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

  // On syncStrand, when an entry is written or a submission refused: the
  // group is synced now, or once the submissions being written join it.
  void groupChanged() {
    if (toSync.empty()) return;
    if (beingWritten.load() == 0 || toSync.size() >= kLargestGroup) return syncSubmissions();
    if (groupTimerSet) return;
    groupTimerSet = true;
    groupTimer.expires_after(kGroupWait);
    groupTimer.async_wait([this](const boost::system::error_code& error) {
      groupTimerSet = false;
      if (!error && !toSync.empty()) syncSubmissions();
    });
  }

  // On syncStrand: one syncfs for every entry written so far.
  void syncSubmissions() {
    auto batch = std::move(toSync);
    toSync.clear();
    std::vector<Spool::Entry*> entries;
    for (const auto& pending : batch) entries.push_back(&pending->entry);
    try {
      Spool::Entry::commitAll(entries);
    } catch (const std::exception& error) {
      log->error("submissions refused: {}", error.what());
      for (const auto& pending : batch) {
        pending->done({507, {{"error", fmt::format("the job was not accepted: {}", error.what())}}});
      }
      return;  // the entries go with the batch
    }
    onStrand([this, batch = std::move(batch)] {
      toAdd.insert(toAdd.end(), batch.begin(), batch.end());
      if (toAdd.size() == batch.size()) onStrand([this] { addSubmissions(); });
    });
  }

  // On the strand: the rows of every submission synced so far, in one transaction.
  void addSubmissions() {
    auto batch = std::move(toAdd);
    toAdd.clear();
    const auto refuseAll = [&](int status, const std::string& why) {
      for (const auto& pending : batch) {
        std::error_code ignored;
        fs::remove_all(pending->entry.folder(), ignored);
        pending->done({status, {{"error", why}}});
      }
    };
    if (stopping) return refuseAll(503, "the daemon is stopping");
    std::vector<NewJob> jobs;
    std::vector<std::string> reasons;
    for (const auto& pending : batch) {
      jobs.push_back(pending->job);
      reasons.push_back(fmt::format("submitted by {}", pending->job.owner));
    }
    std::vector<JobRecord> added;
    try {
      added = store->addJobs(jobs, reasons);
    } catch (const StoreError& error) {
      log->error("{}", error.what());
      return refuseAll(507, error.what());
    } catch (const std::exception& error) {
      log->error("{}", error.what());
      return refuseAll(500, error.what());
    }
    for (size_t i = 0; i < added.size(); ++i) {
      log->info("job {}: {} submitted by {}{}", added[i].id, added[i].source, added[i].owner,
                added[i].state == JobState::Queued
                    ? ""
                    : fmt::format("; {}: {}", stateName(added[i].state), added[i].message));
      jobChanged(added[i]);
      batch[i]->done({201, jobJson(added[i])});
    }
    pump();
  }

  void finishIfStopping() {
    if (!stopping || !cuts.empty() || !planning.empty() || !stopped) return;
    auto done = std::move(stopped);
    stopped = nullptr;
    done();
  }

  // ---- actions ----

  Reply act(JobId id, const std::string& action, const json& arguments, const std::string& who) {
    if (stopping) throw ApiError(503, "the daemon is stopping");
    const JobRecord job = jobOrThrow(id);
    const auto refuse = [&](const std::string& why) -> Reply {
      throw ApiError(409, fmt::format("job {} is {}{}", id, stateName(job.state), why));
    };
    // A cut or plan of this host's is stopped whatever the store says of its
    // job (released to another host meanwhile, the laser must still go off).
    if (action == "cancel" && (cuts.contains(id) || planning.contains(id)) && store->shared() &&
        !(job.host == config.host && heldByAHost(job.state))) {
      if (auto c = cuts.find(id); c != cuts.end()) {
        c->second->cancelledBy = who;
        c->second->control->cancel.cancel();
        if (c->second->waiting) {
          c->second->waiting->set_value(false);
          c->second->waiting.reset();
        }
      }
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
        (action == "cancel" || action == "pause" || action == "resume" || action == "next")) {
      if (action == "pause" && job.state != JobState::Running) refuse("; only a running job can be paused");
      if (action == "resume" && job.state != JobState::Paused) {
        refuse("; only a paused, interrupted or failed job can be resumed");
      }
      if (action == "next" && job.state != JobState::Running)
        refuse("; only a job waiting between sheets takes `next`");
      ActionRequest request;
      request.job = id;
      request.action = action;
      request.arguments = arguments.is_null() ? "{}" : arguments.dump();
      request.who = who;
      if (const auto holder = store->requestAction(request)) {
        json answer = jobJson(job);
        answer["asked_host"] = *holder;
        store->addEvent(id, "asked", fmt::format("{} asked host {} to {} it", who, *holder, action));
        return {202, answer};
      }
      return act(id, action, arguments, who);  // (released to no host, or to this one, meanwhile)
    }
    // (Held by this host, a job is in `planning` or `cuts` until it leaves that state.)
    const bool ours = job.host.empty() || job.host == config.host;
    if (ours && ((job.state == JobState::Planning && !planning.contains(id)) ||
                 (holdsDevice(job.state) && !cuts.contains(id)))) {
      refuse(", but this daemon is not working on it (it is being released); ask again in a moment");
    }
    if (action == "cancel") {
      if (job.state == JobState::Planning) {
        planning[id].cancelledBy = who;
        planning[id].cancel->cancel();
        return {202, jobJson(job)};
      }
      if (holdsDevice(job.state)) {
        Cut& cut = *cuts.at(id);
        cut.cancelledBy = who;
        // (A paused job stays held: the driver sees the cancel in its hold
        // and stops from there, without moving again.)
        cut.control->cancel.cancel();
        if (cut.waiting) {
          cut.waiting->set_value(false);
          cut.waiting.reset();
        }
        return {202, jobJson(job)};
      }
      if (job.state == JobState::Done || job.state == JobState::Cancelled) refuse("; there is nothing to cancel");
      const JobRecord cancelled = record(id, JobState::Cancelled, fmt::format("cancelled by {}", who));
      jobChanged(cancelled);
      pump();
      return {200, jobJson(cancelled)};
    }
    if (action == "pause") {
      if (job.state != JobState::Running) refuse("; only a running job can be paused");
      Cut& cut = *cuts.at(id);
      if (cut.waiting) refuse(", waiting for the next sheet: nothing moves, so there is nothing to pause");
      if (auto* run = cut.control->run.load()) run->pause();
      const JobRecord paused = record(id, JobState::Paused, fmt::format("paused by {}", who));
      devices[cut.device].state = "paused";
      deviceChanged(devices[cut.device]);
      jobChanged(paused);
      return {200, jobJson(paused)};
    }
    if (action == "resume") {
      if (job.state == JobState::Paused) {
        Cut& cut = *cuts.at(id);
        if (auto* run = cut.control->run.load()) run->resume();
        const JobRecord running = record(id, JobState::Running, fmt::format("resumed by {}", who));
        devices[cut.device].state = "running";
        deviceChanged(devices[cut.device]);
        jobChanged(running);
        return {200, jobJson(running)};
      }
      if (job.state == JobState::Interrupted || job.state == JobState::Failed) {
        if (job.sheets == 0) refuse("; it was never planned: submit it again");
        if (!arguments.contains("from_sheet") || !arguments["from_sheet"].is_number_integer()) {
          throw ApiError(400, fmt::format("job {} stopped {}: say which sheet to go on from, with --from-sheet N "
                                          "(from_sheet), once that sheet is loaded",
                                          id, sheetWhere(job.sheet, job.sheets, job.stroke, job.strokes)));
        }
        const int from = arguments["from_sheet"].get<int>();
        startCut(job, from, fmt::format("resumed by {} from sheet {}", who, from));
        return {200, jobJson(store->job(id).value())};
      }
      refuse("; only a paused, interrupted or failed job can be resumed");
    }
    if (action == "start") {
      if (job.state != JobState::Ready) {
        refuse(job.state == JobState::Queued || job.state == JobState::Planning ? "; it can start once it is planned"
                                                                                : "; only a ready job can be started");
      }
      startCut(job, 1, fmt::format("started by {}", who));
      return {200, jobJson(store->job(id).value())};
    }
    if (action == "next") {
      auto c = cuts.find(id);
      if (c == cuts.end() || !c->second->waiting) {
        refuse(
            job.state == JobState::Running
                ? fmt::format(", cutting sheet {} of {}: it is not waiting for the next sheet", job.sheet, job.sheets)
                : std::string("; only a job waiting between sheets takes `next`"));
      }
      c->second->waiting->set_value(true);
      c->second->waiting.reset();
      store->addEvent(id, "next", fmt::format("{} loaded sheet {}", who, job.sheet + 1));
      return {200, jobJson(job)};
    }
    if (action == "move") {
      if (isFinal(job.state) && job.state != JobState::Interrupted && job.state != JobState::Failed) {
        refuse("; only a job still to cut has a place in the queue");
      }
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
        throw ApiError(400, "move needs before (a job number) or priority (a whole number)");
      }
      store->reorder(id, priority, position);
      store->addEvent(id, "move", fmt::format("moved by {}", who));
      const JobRecord moved = store->job(id).value();
      jobChanged(moved);
      return {200, jobJson(moved)};
    }
    throw ApiError(404, fmt::format("no action {} (cancel, pause, resume, start, next, move)", action));
  }
};

Service::Service(asio::io_context& io, DaemonConfig config, std::shared_ptr<spdlog::logger> log)
    : config_(std::move(config)) {
  impl_ = std::make_unique<Impl>(io, config_, std::move(log));
}

Service::~Service() {
  // The heartbeat's timer is let go, so that the strand's pool can finish.
  std::promise<void> quiet;
  asio::post(impl_->strand, [this, &quiet] {
    impl_->stopping = true;
    if (impl_->ticker) impl_->ticker->cancel();
    impl_->diskTimer.cancel();
    quiet.set_value();
  });
  quiet.get_future().wait();
  impl_->watching = false;
  if (impl_->watchdog.joinable()) impl_->watchdog.join();
  // Whatever is still posted finishes; the planners see their cancel.
  for (auto& [id, planning] : impl_->planning) planning.cancel->cancel();
  for (auto& [id, cut] : impl_->cuts) cut->control->cancel.cancel();
  impl_->planners.join();
  for (std::thread& check : impl_->checks) {
    if (check.joinable()) check.join();
  }
  impl_->workers.join();
  impl_->syncer.join();  // (after the workers, who hand it entries; before the strand it hands rows)
  impl_->state.join();
  for (auto& [id, cut] : impl_->cuts) {
    if (cut->thread.joinable()) cut->thread.join();
  }
}

void Service::start() {
  impl_->open();
  std::promise<void> recovered;
  auto done = recovered.get_future();
  impl_->onStrand([this, &recovered] {
    try {
      impl_->join();
      recovered.set_value();
    } catch (...) {
      recovered.set_exception(std::current_exception());
    }
  });
  done.get();
  impl_->onStrand([this] {
    if (impl_->diskFull) impl_->watchDisk();
    impl_->checkDevices();
    impl_->pump();
  });
}

void Service::submit(Submission submission, ReplyHandler done) {
  Impl& impl = *impl_;
  // The bytes go to the spool off the strand; the row once they are durable.
  ++impl.beingWritten;
  asio::post(impl.workers, [&impl, submission = std::move(submission), done = std::move(done)]() mutable {
    // However the submission ends, its entry (if it has one) goes to be
    // synced, and the group commit stops waiting for it.
    struct Written {
      Impl& impl;
      std::shared_ptr<Impl::Pending> pending;
      ~Written() {
        asio::post(impl.syncStrand, [&impl = impl, pending = std::move(pending)] {
          if (pending) impl.toSync.push_back(pending);
          --impl.beingWritten;
          impl.groupChanged();
        });
      }
    } written{impl, nullptr};
    NewJob job;
    job.owner = submission.owner;
    job.device = submission.device;
    job.priority = submission.priority;
    if (submission.options) job.options = jobs::optionsJson(*submission.options).dump();
    std::optional<Spool::Entry> entry;
    Reply refused;
    refused.status = 0;
    try {
      if (impl.stopping) throw ApiError(503, "the daemon is stopping");
      if (impl.diskFull) throw ApiError(507, impl.diskFullRefusal());
      if (!submission.device.empty()) {
        // (Any host's: on a shared store a job may be submitted here for a device of another.)
        std::string why;
        if (!impl.deviceFor(submission.device, "", why)) throw ApiError(400, why);
      }
      if (submission.upload) {
        // (Its mesh already written, a piece at a time, as it arrived: UploadForm.h.)
        entry.emplace(std::move(*submission.upload));
        submission.upload.reset();
        job.kind = JobKind::Mesh;
        job.source = submission.fileName;
        if (!submission.options) throw ApiError(400, kNoStructure);
      } else {
        entry.emplace(impl.spool->begin());
        const fs::path path = submission.path;
        std::error_code error;
        if (path.empty() || !path.is_absolute()) {
          throw ApiError(400,
                         fmt::format("path \"{}\": expected an absolute path on the daemon's machine", path.string()));
        }
        if (fs::is_directory(path, error)) {
          if (submission.options) {
            throw ApiError(400, fmt::format("{}: a planned folder is cut as it was made; make options are for a mesh",
                                            path.string()));
          }
          if (!fs::is_regular_file(path / "manifest.json", error)) {
            throw ApiError(400, fmt::format("{}: not an output folder of `rotafab make`: it holds no manifest.json",
                                            path.string()));
          }
          job.kind = JobKind::Planned;
          job.source = shownText(path.string(), 1000);
          // A folder that is not a make output, or whose sheets are wrong, is refused at once.
          std::ifstream manifestFile(path / "manifest.json");
          char first = 0;
          manifestFile >> first;
          if (first != '{') {
            throw ApiError(400, fmt::format("{}: manifest.json is not a manifest (not a JSON object)", path.string()));
          }
          entry->addFolder(path);
          impl.planOnSubmission(job, entry->folder(), path);
        } else if (fs::is_regular_file(path, error)) {
          job.kind = JobKind::Mesh;
          job.source = cleanFileName(path.filename().string());
          if (job.source.empty() || job.source.starts_with("planned")) {
            throw ApiError(400, fmt::format("{}: not a mesh file's name", shownText(path.string(), 1000)));
          }
          if (!submission.options) throw ApiError(400, kNoStructure);
          // Copied a piece at a time: a mesh of any size is never whole in the daemon's memory.
          try {
            entry->copyFile(job.source, path);
          } catch (const std::exception& failed) {
            if (saysDiskFull(failed.what())) throw;
            throw ApiError(400, fmt::format("{}: cannot read the file", shownText(path.string(), 1000)));
          }
        } else {
          throw ApiError(400, fmt::format("{}: no such file or folder on the daemon's machine", path.string()));
        }
      }
      job.spool = entry->name();
    } catch (const ApiError& error) {
      refused = {error.status, {{"error", error.what()}}};
    } catch (const core::UserError& error) {
      refused = {400, {{"error", error.what()}}};
    } catch (const std::exception& error) {
      const std::string what = error.what();
      const bool full = saysDiskFull(what);
      refused = {full ? 507 : 500,
                 {{"error", full ? fmt::format("the spool's disk is full; the job was not accepted ({})", what)
                                 : fmt::format("the job was not accepted: {}", what)}}};
      impl.log->error("submission refused: {}", what);
    }
    if (refused.status != 0) {
      // The half-written entry, or the refused upload, goes before the caller is told.
      entry.reset();
      submission.upload.reset();
      done(refused);
      return;
    }
    // Synced to disk with whatever else came in meanwhile, then added with it.
    written.pending = std::make_shared<Impl::Pending>(Impl::Pending{std::move(*entry), job, std::move(done)});
  });
}

Spool::Entry Service::beginUpload() {
  if (impl_->stopping) throw ApiError(503, "the daemon is stopping");
  if (impl_->diskFull) throw ApiError(507, impl_->diskFullRefusal());
  try {
    return impl_->spool->begin();
  } catch (const std::exception& error) {
    impl_->log->error("an upload cannot be kept: {}", error.what());
    if (saysDiskFull(error.what())) throw ApiError(507, "the spool's disk is full; the job was not accepted");
    throw ApiError(500, "the daemon cannot keep an upload in its spool (its log says why)");
  }
}

void Service::list(ReplyHandler done) {
  impl_->answer(std::move(done), [this] {
    // Written a job at a time: the text, not a tree of every job (10,000 jobs: 6 MB, not 45).
    Reply reply;
    reply.text = R"({"jobs":[)";
    bool first = true;
    impl_->store->eachJob([&](const JobRecord& job) {
      if (!first) reply.text += ',';
      first = false;
      reply.text += impl_->jobJson(job).dump(-1, ' ', false, json::error_handler_t::replace);
    });
    reply.text += "]}\n";
    return reply;
  });
}

void Service::status(JobId id, ReplyHandler done) {
  impl_->answer(std::move(done), [this, id] {
    const JobRecord job = impl_->jobOrThrow(id);
    json out = impl_->jobJson(job);
    json transitions = json::array();
    for (const Transition& t : impl_->store->transitions(id)) {
      transitions.push_back({{"from", t.from ? json(stateName(*t.from)) : json(nullptr)},
                             {"to", stateName(t.to)},
                             {"at", isoTime(t.at)},
                             {"reason", t.reason}});
    }
    out["transitions"] = transitions;
    return Reply{200, out};
  });
}

void Service::manifest(JobId id, ReplyHandler done) {
  impl_->answer(std::move(done), [this, id] {
    const JobRecord job = impl_->jobOrThrow(id);
    if (job.sheets == 0) {
      throw ApiError(409,
                     fmt::format("job {} is {}: it has no manifest until it is planned", id, stateName(job.state)));
    }
    std::ifstream in(impl_->plannedFolder(job) / "manifest.json");
    json manifest = json::parse(in, nullptr, false);
    if (manifest.is_discarded()) throw ApiError(500, fmt::format("job {}: its manifest.json cannot be read", id));
    return Reply{200, manifest};
  });
}

void Service::file(JobId id, const std::string& name, ReplyHandler done) {
  impl_->answer(std::move(done), [this, id, name] {
    const JobRecord job = impl_->jobOrThrow(id);
    // Only what a planned job's folder holds for people to look at, by its own names.
    static const std::regex kShown(R"((sheet-\d{3,}\.(svg|preview\.svg))|structure\.obj|manifest\.txt|manifest\.json)");
    if (!std::regex_match(name, kShown)) {
      throw ApiError(404, fmt::format("no file {} (sheet-NNN.preview.svg, sheet-NNN.svg, structure.obj, "
                                      "manifest.txt, manifest.json)",
                                      name));
    }
    if (job.sheets == 0) {
      throw ApiError(409, fmt::format("job {} is {}: it has no files until it is planned", id, stateName(job.state)));
    }
    const fs::path path = impl_->plannedFolder(job) / name;
    std::error_code error;
    if (!fs::is_regular_file(path, error)) throw ApiError(404, fmt::format("job {} has no {}", id, name));
    Reply reply;
    reply.file = path;
    return reply;
  });
}

void Service::sheet(JobId id, int sheet, ReplyHandler done) {
  // The job and its device's profiles on the strand; the toolpath, which may
  // take a while on a sheet of thousands of strokes, on the workers.
  impl_->onStrand([this, id, sheet, done = std::move(done)]() mutable {
    std::function<Reply()> work;
    const Reply refused = impl_->guarded([&] {
      const JobRecord job = impl_->jobOrThrow(id);
      if (job.sheets == 0) {
        throw ApiError(409,
                       fmt::format("job {} is {}: it has no sheets until it is planned", id, stateName(job.state)));
      }
      if (sheet < 1 || sheet > job.sheets) {
        throw ApiError(404, fmt::format("job {} has sheets 1 to {}, not {}", id, job.sheets, sheet));
      }
      std::string why;
      const std::optional<Impl::Target> device = impl_->deviceFor(job.device, "", why);
      if (!device) throw ApiError(409, fmt::format("job {} has no device to plan its strokes for", id));
      work = [folder = impl_->plannedFolder(job), machine = device->machine, material = device->material, sheet, id] {
        const std::vector<jobs::JobSheet> drawn = jobs::readJobSheets(folder, std::optional<int>(sheet));
        if (drawn.empty()) throw ApiError(404, fmt::format("job {} has no sheet {}", id, sheet));
        const jobs::Toolpath path =
            jobs::planToolpath(drawn.front().drawing, machine, material, jobs::profileMotion(machine));
        json answer = toolpathJson(path);
        // Each operation in its colour of the machine's table (fig. 65), as the sheet files draw it.
        json colours = json::object();
        for (profiles::Operation operation : profiles::kAllOperations) {
          const profiles::Rgb rgb = machine.settingFor(operation).rgb;
          colours[std::string(profiles::operationName(operation))] =
              fmt::format("#{:02x}{:02x}{:02x}", rgb.r, rgb.g, rgb.b);
        }
        answer["colours"] = std::move(colours);
        return Reply{200, std::move(answer)};
      };
      return Reply{0, nullptr};
    });
    if (refused.status != 0) return done(refused);
    asio::post(impl_->workers, [this, work = std::move(work), done = std::move(done)] { done(impl_->guarded(work)); });
  });
}

void Service::devices(ReplyHandler done) {
  impl_->answer(std::move(done), [this] {
    json all = json::array();
    for (const auto& device : impl_->devices) all.push_back(impl_->deviceJson(device));
    if (!impl_->store->shared()) return Reply{200, {{"devices", all}}};
    // On a shared store, the other hosts' devices as their hosts last said, and the hosts.
    json hosts = json::array();
    std::set<std::string> gone;
    for (const HostRecord& host : impl_->store->hosts()) {
      if (host.gone) gone.insert(host.name);
      json entry{{"name", host.name},
                 {"address", host.address},
                 {"state", host.gone ? "gone" : "up"},
                 {"seen", isoTime(host.seen)}};
      hosts.push_back(std::move(entry));
    }
    for (const DeviceRecord& device : impl_->store->devices()) {
      if (device.host == impl_->config.host) continue;
      json entry{{"name", device.name},
                 {"host", device.host},
                 {"uri", device.uri},
                 {"machine", device.machine},
                 {"material", device.material},
                 {"auto_start", device.autoStart},
                 {"state", gone.contains(device.host) ? "gone" : device.state}};
      if (!device.message.empty()) entry["message"] = device.message;
      entry["job"] = device.job ? json(*device.job) : json(nullptr);
      all.push_back(std::move(entry));
    }
    return Reply{200, {{"devices", all}, {"hosts", hosts}}};
  });
}

void Service::act(JobId id, const std::string& action, const json& arguments, const std::string& who,
                  ReplyHandler done) {
  impl_->answer(std::move(done), [this, id, action, arguments, who] { return impl_->act(id, action, arguments, who); });
}

size_t Service::subscribe(std::function<void(const ServiceEvent&)> sink) {
  std::promise<size_t> id;
  auto result = id.get_future();
  impl_->onStrand([this, &id, sink = std::move(sink)]() mutable {
    const size_t next = impl_->nextSubscriber++;
    impl_->subscribers[next] = std::move(sink);
    id.set_value(next);
  });
  return result.get();
}

void Service::unsubscribe(size_t id) {
  impl_->onStrand([this, id] { impl_->subscribers.erase(id); });
}

void Service::shutdown(const std::string& why, std::function<void()> done) {
  impl_->onStrand([this, why, done = std::move(done)]() mutable {
    Impl& impl = *impl_;
    impl.stopping = true;  // (the heartbeat goes on until every cut has stopped; no more claims)
    impl.stopped = std::move(done);
    impl.log->info("stopping ({}): {} cut{} and {} plan{} to stop", why, impl.cuts.size(),
                   impl.cuts.size() == 1 ? "" : "s", impl.planning.size(), impl.planning.size() == 1 ? "" : "s");
    for (auto& [id, planning] : impl.planning) planning.cancel->cancel();
    for (auto& [id, cut] : impl.cuts) Impl::stopCutByItself(*cut, "");
    impl.finishIfStopping();
  });
}

}  // namespace rotafab::service
