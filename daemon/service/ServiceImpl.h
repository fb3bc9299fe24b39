#pragma once
// The service's state and its parts (Service.h says what the service is
// and its thread rules). One Impl holds the queue's state, touched only on
// its strand; its work is defined by concern, a file each:
//   Service.cpp             the facade, the reply guard, lookups
//   ServiceViews.cpp        the API's JSON views and the events
//   ServiceDisk.cpp         a full disk: the reserve, unrecorded transitions
//   ServiceHosts.cpp        start, the shared store's lease and its watchdog, device checks
//   ServicePlanning.cpp     the queue's pump and planning
//   ServiceCutting.cpp      cuts on their threads
//   ServiceSubmissions.cpp  submissions and their group commit
//   ServiceActions.cpp      the operator's actions

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
#include "daemon/service/Notifier.h"
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

// A mesh submitted without options: as `rotafab make` says it.
inline constexpr const char* kNoStructure = "make options: --structure is required";

// An ISO 8601 time, UTC, to the second.
std::string isoTime(double unixSeconds);

// A job's `make` options as the store keeps them (an object of options; a
// list of words in stores written before), read by make's table.
std::optional<jobs::MakeOptions> storedOptions(const std::string& stored);

// A message about a file in the spool, in the words of the file the
// submitter named: the spool's folder dropped, or said as `submitted`.
std::string inSubmittersWords(std::string message, const fs::path& folder, const fs::path& submitted = {});

// Where a cut stopped, for messages: "at sheet 2 of 4, after stroke 10 of 90".
std::string sheetWhere(int sheet, int sheets, int64_t stroke, int64_t strokes);
// How a job stopped in `sheet` with `cut` of its strokes cut goes on: from
// the next stroke, after a frame; from the sheet's start when none or all were cut.
std::string goOnSaid(int sheet, int64_t cut, int64_t strokes);

// Between a running job's driver thread and the strand.
// A text of a job's summary (its "stock", "machine", "units", "folder"),
// empty where it has none.
std::string summaryText(const JobRecord& job, const char* key);

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
    // Set while the job waits for its operator: `next` cuts, `frame` traces
    // the sheet first, a cancel stops. `waitingFor` says for what.
    std::optional<std::promise<devices::SheetGo>> waiting;
    std::string waitingFor;
    bool frameOnly = false;  // a frame of a job not being cut: its state stays as it was
    int sheet = 1;           // the sheet framed (frameOnly), or waited for
    // Between sheets (starting one, framing it, waiting for its operator):
    // nothing moves that a pause could hold, and the driver's next run
    // would forget a hold asked now.
    bool between = true;
    std::string stateBefore, messageBefore;  // the device's, before a frame (frameOnly)
    std::string cancelledBy;
    std::string stoppedBecause;  // stopped by the daemon for this (a full disk): interrupted
    Clock::time_point lastStored{}, lastSent{};
    int64_t storedCut = -1;  // the strokes cut, as last stored
  };

  Impl(asio::io_context& io, const DaemonConfig& config, std::shared_ptr<spdlog::logger> log)
      : io(io),
        config(config),
        log(std::move(log)),
        planners(config.planners),
        executor(std::make_unique<core::Executor>(std::max(1u, std::thread::hardware_concurrency()))),
        notifier(config.notify.any() ? std::make_unique<Notifier>(config.notify, this->log) : nullptr) {}

  asio::io_context& io;
  const DaemonConfig& config;
  std::shared_ptr<spdlog::logger> log;
  asio::thread_pool state{1};
  asio::strand<asio::thread_pool::executor_type> strand{state.get_executor()};
  asio::thread_pool workers{2};
  asio::thread_pool planners;
  std::unique_ptr<core::Executor> executor;
  std::unique_ptr<JobStore> store;
  std::unique_ptr<Notifier> notifier;  // none when no receiver is configured
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

  // The devices of the other live hosts, as the last heartbeat found them;
  // read off the strand too (a planned folder's submission), hence the lock.
  mutable std::mutex othersMutex;
  std::vector<Target> others;
  std::function<void()> stopped;

  // ---- lookups and the reply guard (Service.cpp) ----

  template <typename Work>
  void onStrand(Work&& work) {
    asio::post(strand, std::forward<Work>(work));
  }

  // Runs `work` on the strand and replies with what it returns, or the error it throws.
  void answer(ReplyHandler done, std::function<Reply()> work);

  Reply guarded(const std::function<Reply()>& work);

  Device* deviceNamed(const std::string& name);

  std::string deviceNames() const;

  JobRecord jobOrThrow(JobId id);

  fs::path plannedFolder(const JobRecord& job) const;

  // ---- the API's views and events (ServiceViews.cpp) ----

  void publish(const std::string& type, json data);

  json deviceJson(const Device& device) const;

  // The job as the store has it, with the transitions a full disk kept from being recorded.
  JobRecord withUnrecorded(JobRecord job) const;

  json jobJson(const JobRecord& stored) const;

  void jobChanged(const JobRecord& job);

  void deviceChanged(const Device& device);

  // ---- a full disk (ServiceDisk.cpp) ----

  static constexpr std::string_view kDiskFull = "the disk that holds the daemon's state is full";

  std::string diskFullRefusal() const;

  // A write to the store failed: a full disk is a state of its own
  // (diskBecameFull); anything else is logged.
  void storeTrouble(const std::string& what, const std::exception& error);

  // A cut this daemon stops by itself, for `because` (empty: its stop): laser off, left interrupted.
  static void stopCutByItself(Cut& cut, const std::string& because);

  // A write of the store found no room: the reserve's room is given back
  // (so that what ends now can be recorded), every cut stops with its laser
  // off and is left interrupted (its progress could no longer be kept),
  // every plan stops and is queued again, and nothing new is taken on until
  // the disk has room again (watchDisk). Said once in the log, not at every write.
  void diskBecameFull(const std::string& why);

  // While the disk is full: every 2 s, what was kept from the store is
  // written if it can be, and once the disk has room for the reserve and as
  // much again, the reserve is made again and the queue goes on.
  void watchDisk();

  // A transition the store must record; on a full disk, with the reserve's
  // room. With `keepIfFull` (the end of a cut or a plan, which has happened
  // whatever the disk says) one that even that cannot record is kept in
  // `unrecorded`, shown as done, and written once it can be; otherwise the
  // StoreError goes to the caller (an operator's action is refused, 507).
  JobRecord record(JobId id, JobState to, const std::string& reason, const JobChange& change = {},
                   bool keepIfFull = false);

  void writeUnrecorded();
  JobRecord recordInStore(JobId id, JobState to, const std::string& reason, const JobChange& change, bool keepIfFull);

  // An event for the webhooks and the MQTT broker (Notifier.h): its kind,
  // the job's number, source, device, state, sheets, message and `extra`.
  void notify(const JobRecord& job, const std::string& kind, json extra) noexcept;

  // ---- this host: its start, its lease on a shared store, its devices' checks (ServiceHosts.cpp) ----

  // The lease renewed by a heartbeat sent at `sent`: safe until 4/5 of a lease after it.
  void leaseRenewed(Clock::time_point sent);
  // The watchdog's loop (its own thread).
  void watchLease();

  void open();

  // What becomes of a job whose host stopped: cut, it is interrupted (never
  // restarted by itself); planned, it is planned again. `who`: "the daemon"
  // after this host's own stop, else the host whose lease ran out.
  static std::pair<JobState, std::string> released(const JobRecord& job, const std::string& who);

  DeviceRecord deviceRecord(const Device& device) const;

  // This host into the store (again, after its lease ran out), and what it
  // held before released: jobs it was cutting become interrupted, plans it
  // was making are made again. `wait`: seconds to wait for a lease this
  // host's name still holds (a daemon killed a moment ago holds it a little longer).
  void joinStore(double wait);

  // At the start: into the store; spool folders no job names (a stop
  // mid-submission) removed; on a shared store, the heartbeat started.
  void join();

  // On a shared store, twice a second: work the other hosts added; five
  // times a lease, the heartbeat, and the hosts whose lease ran out.
  void tick();

  void beat();

  // This host's lease ran out (it was stalled, or cut off from the store):
  // another host may take its jobs, so it stops them at once, lasers off,
  // and joins the store again (which releases what it still held).
  void fence(const std::string& why);

  // The actions other hosts left for this host's jobs, done as if asked here.
  void serveRequests();

  void refreshOthers();

  // " (http://HOST:PORT)" where another host's API answers, when it said.
  std::string hostAddressSaid(const std::string& host);

  // Every device is stopped safely before anything is cut: whatever a run
  // before this daemon left behind (a kill -9 mid-cut leaves a real GRBL
  // burning through what it had buffered), its laser is off.
  void checkDevices();

  // ---- the queue and planning (ServicePlanning.cpp) ----

  // Starts what can start: plans for queued jobs while a planner is free,
  // and cuts of ready jobs on idle devices configured to start by themselves.
  // Each job is claimed from the store (JobStore::claim), so that on a
  // shared store no two hosts plan or cut the same one.
  void pump();

  static Target targetOf(const Device& device, const std::string& host);

  // The device a job is planned against: the one it names, or the first
  // (this host's before the others') whose machine profile the job's
  // options do not rule out. It reads only what open() set and the other
  // hosts' devices under their lock, so a submission may ask it off the strand.
  // `madeFor`: the machine a planned folder was made for, unless the options name one.
  std::optional<Target> deviceFor(const std::string& named, const std::string& options, std::string& why,
                                  const std::string& madeFor = "") const;

  static std::string planningReason(const Target& device);

  static std::string plannedReason(int sheets);

  // A planned folder's plan: its sheets read and checked against the bed
  // they are to be cut on; the summary the queue shows, from its manifest.
  json planOfFolder(const fs::path& folder, const profiles::MachineProfile& machine,
                    const profiles::MaterialProfile& material) const;

  // A planned folder is planned while it is submitted (off the strand, in
  // the submission's worker): its job is added ready, its queued, planning
  // and ready recorded in the one transaction that adds it, where planning
  // it from the queue would cost two more synced commits. A folder whose
  // sheets are unreadable, or too large for the device's bed, is refused
  // then and there, in the words of the folder the submitter named.
  void planOnSubmission(NewJob& job, const fs::path& folder, const fs::path& submitted);

  // A job this host claimed to plan (planning, its device set): planned on a planner.
  void startPlanning(const JobRecord& job, const Target& device);

  // On a planner: the job's plan, against its device's profiles.
  void plan(const JobRecord& job, const profiles::MachineProfile& machine, const profiles::MaterialProfile& material,
            const std::shared_ptr<core::Cancellation>& cancel);

  // ---- cuts (ServiceCutting.cpp) ----

  // What a cut from `fromSheet` on `device` changes in its job.
  static JobChange cutFromSheet(int fromSheet, const std::string& device);

  // The device of this host a job is cut on: its own, or, for a job
  // submitted for any device, one of this host's of the same machine.
  // Otherwise another host's device: the job is started there.
  Device& localDeviceFor(const JobRecord& job);

  // `fromStroke` (0-based): the strokes of the first sheet cut before; the
  // cut frames that sheet and waits for its operator before it goes on.
  void startCut(const JobRecord& job, int fromSheet, const std::string& reason, int64_t fromStroke = 0);

  // Where a job's cut would go on: the device it would be cut on, idle.
  Device& idleDeviceFor(const JobRecord& job);

  // A job this host moved to running on `device` (or, `frameOnly`, whose
  // sheet `fromSheet` is framed on it): its cut on a thread of its own.
  void launchCut(const JobRecord& job, Device& on, int fromSheet, int64_t fromStroke, bool frameOnly = false);

  // The frame of a sheet: of the job waiting for its next sheet, traced by
  // its cut; of a job not being cut, on the device it would be cut on.
  Reply frameJob(const JobRecord& job, const json& arguments, const std::string& who);

  // A job not being planned or cut moved to the device `name`: as it is
  // where that device's machine is the one its sheets were planned for; a
  // ready mesh's planned again otherwise; refused where that cannot be.
  Reply moveToDevice(const JobRecord& job, const std::string& name, const std::string& who);

  // The material a planned job is cut with: the one its manifest names (it
  // was made for it: kerf, power, speed, passes), else the device's.
  // Throws profiles::ProfileError when no profile here has the job's. Reads
  // the catalogue only, which no thread changes after startup.
  [[nodiscard]] profiles::MaterialProfile cuttingMaterial(const fs::path& folder,
                                                          const profiles::MaterialProfile& device) const;

  // On the job's own thread: the driver's loop, its events posted to the strand.
  struct CutSetup {
    std::string uri;
    profiles::MachineProfile machine;
    profiles::MaterialProfile material;
    fs::path folder;
    int fromSheet = 1, sheets = 0;
    int64_t fromStroke = 0;
    bool frameOnly = false;
  };
  void runCut(JobId id, const std::shared_ptr<RunControl>& control, const CutSetup& setup);
  // On the cut's thread: waits until the operator says what to do, the
  // job told as waiting for `what` ("sheet 3 to be loaded").
  devices::SheetGo waitForOperator(JobId id, const std::shared_ptr<RunControl>& control, int sheet,
                                   const std::string& what);

  void cutProgress(JobId id, const devices::Progress& progress, int sheets);

  void cutEnded(JobId id, const std::optional<devices::DeviceFault>& fault, const std::optional<std::string>& failure,
                const devices::RunSummary& summary);

  // A frame of a job not being cut has ended: said in the job's events.
  void frameEnded(JobId id, const Cut& cut, Device& device, const std::optional<devices::DeviceFault>& fault,
                  const std::optional<std::string>& failure);

  // A stop asked for, once every cut and plan has ended: its `done` called.
  void finishIfStopping();

  // ---- submissions and their group commit (ServiceSubmissions.cpp) ----

  // On syncStrand, when an entry is written or a submission refused: the
  // group is synced now, or once the submissions being written join it.
  void groupChanged();

  // On syncStrand: one syncfs for every entry written so far.
  void syncSubmissions();

  // On the strand: the rows of every submission synced so far, in one transaction.
  void addSubmissions();

  // ---- actions (ServiceActions.cpp) ----

  // cancel, pause, resume, start, next, move, as Service::act says.
  Reply act(JobId id, const std::string& action, const json& arguments, const std::string& who);
  // An action on a job another host holds: left for that host in the store.
  Reply askItsHost(const JobRecord& job, const std::string& action, const json& arguments, const std::string& who);
  Reply cancelJob(const JobRecord& job, const std::string& who);
  // A cut told to stop by `who`, its laser off; one waiting for its next sheet stops there.
  static void cancelCut(Cut& cut, const std::string& who);
  Reply pauseJob(const JobRecord& job, const std::string& who);
  Reply resumeJob(const JobRecord& job, const json& arguments, const std::string& who);
  Reply nextSheet(const JobRecord& job, const std::string& who);
  Reply moveJob(const JobRecord& job, const json& arguments, const std::string& who);
};

}  // namespace rotafab::service
