#pragma once
// Where the daemon keeps its jobs (docs/CONTRACT.md, "Daemon"): jobs, every transition
// of each with its time and reason, and events. A small interface of its
// own so that another engine can stand behind it: SQLite (SqliteStore.cpp)
// or PostgreSQL (PostgresStore.cpp), a store several hosts share. Every call
// is one transaction: when it returns, what it wrote survives a kill of the
// process and a loss of power (the engine syncs before it returns). Calls
// come from one thread at a time (the daemon's state strand).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/service/JobState.h"
#include "daemon/service/StoreSchema.h"

namespace rotafab::service {

using JobId = int64_t;

// What a job is made from: a mesh to plan with `make` options, or an already planned `make` output folder.
enum class JobKind { Mesh, Planned };
std::string_view kindName(JobKind kind);

// Fields a transition or a progress report changes with it (unset: unchanged).
struct JobChange {
  std::optional<std::string> device, summary;
  std::optional<int> sheets, sheet;
  std::optional<int64_t> stroke, strokes;
};

// A step a job takes in the very transaction that adds it (a planned folder
// checked while it was submitted is queued, planning and ready in one commit
// rather than three); each allowed by JobState.h from the one before.
struct FirstStep {
  JobState to = JobState::Queued;
  std::function<std::string(JobId)> reason;  // given the job's number, which the store assigns
};

struct NewJob {
  JobKind kind = JobKind::Mesh;
  std::string source;   // the mesh file or folder as the submitter named it (for people)
  std::string owner;    // who submitted it
  std::string device;   // the device asked for; empty: any device whose machine profile fits
  int priority = 0;     // higher first
  std::string options;  // the `make` options, as JSON (an array of command-line words)
  std::string spool;    // its folder in the spool, relative to the spool directory; durable before the job is added
  std::vector<FirstStep> then;  // after its submission, in the same transaction
  JobChange change;             // with the last of `then`
};

struct JobRecord {
  JobId id = 0;
  JobState state = JobState::Queued;
  JobKind kind = JobKind::Mesh;
  std::string source, owner, device, options, spool;
  int priority = 0;
  double position = 0;                // the order within a priority, lower first
  double submitted = 0, updated = 0;  // Unix seconds
  // Once planned: the sheets, and a summary (JSON: panels, sheets, utilization, estimate).
  int sheets = 0;
  std::string summary;
  // How far the cut got: the sheet (1-based; 0 before the first) and the strokes of it acknowledged.
  int sheet = 0;
  int64_t stroke = 0, strokes = 0;
  std::string message;  // the reason of the last transition
  // The host that holds it while it is planning, running or paused (the
  // store sets it: whoever moves a job into one of those states holds it).
  std::string host;
  bool anyDevice = false;  // submitted for any device whose machine profile fits
};

// A daemon on the store, and until when it is taken to be alive (its lease,
// renewed by its heartbeat; by the server's clock where there is one).
struct HostRecord {
  std::string name;
  std::string address;  // where its API answers, for people (its first TCP listener)
  double started = 0, seen = 0, leaseUntil = 0;
  bool gone = false;  // its lease ran out: another host released its jobs
};

// A device as every host sees it: whose it is, and what it is doing.
struct DeviceRecord {
  std::string name, host, machine, material, uri;
  bool autoStart = false;
  std::string state, message;  // idle, running, paused, offline, fault, checking
  std::optional<JobId> job;
};

// An action asked through one host for a job another host holds (cancel,
// pause, resume, next), until the holder takes it.
struct ActionRequest {
  int64_t id = 0;
  JobId job = 0;
  std::string action, arguments, who;  // arguments: JSON
  double at = 0;
};

// What becomes of a job whose host is gone (a restart, a lease run out):
// its new state (queued to be planned again, interrupted) and why.
using Release = std::function<std::pair<JobState, std::string>(const JobRecord& job, const HostRecord& host)>;

// Jobs one host takes for itself, each at most once across every host: up to
// `limit` jobs in state `from`, in queue order, skipping those another host
// is taking at that moment; with `device`, only the jobs for it, and those
// for any device that were planned for a device of its machine and material.
struct ClaimQuery {
  JobState from = JobState::Queued;
  size_t limit = 1;
  std::string device, machine, material;
};
// What the claiming host does with a job: its next state, why, and what changes with it.
struct Claim {
  JobState to = JobState::Planning;
  std::string reason;
  JobChange change;
};

struct Transition {
  JobId job = 0;
  std::optional<JobState> from;  // none: the job's submission
  JobState to = JobState::Queued;
  double at = 0;
  std::string reason;
};

struct Event {
  int64_t id = 0;
  std::optional<JobId> job;
  double at = 0;
  std::string kind, text;
};

// The store cannot do what it was asked (the disk is full, the file is not
// a database, the schema is newer than this program): one line.
class StoreError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What both engines' stores share: the time a change is recorded at (Unix
// seconds), and the check, before anything is written, that each new job's
// first steps are allowed (TransitionRefused naming the job's source).
double unixSeconds();
void checkFirstSteps(const std::vector<NewJob>& jobs);
// TransitionRefused when another host than `host` holds the job.
void checkHolder(const JobRecord& job, const std::string& host);
// What an engine's store writes, in its own SQL, within the caller's
// transaction; each store is one (addJobRows takes the steps they share).
class JobRows {
 public:
  // The new job's row, queued; its number.
  virtual JobId insertRow(const NewJob& job, double position, double at) = 0;
  // A transition's record alone.
  virtual void record(JobId id, std::optional<JobState> from, JobState to, double at, std::string_view reason) = 0;
  // The job's state and message, and the transition's record (TransitionRefused if the table refuses it).
  virtual void move(JobId id, JobState from, JobState to, double at, std::string_view reason) = 0;
  virtual void apply(JobId id, const JobChange& change) = 0;

 protected:
  ~JobRows() = default;
};
// What a claim decides for a job: its move, or nothing (JobStore::claim).
using ClaimDecision = std::function<std::optional<Claim>(const JobRecord&)>;
// Each of `jobs` moved as `decide` says, with its change, in the caller's
// transaction; the numbers of those moved (a claim, a release).
std::vector<JobId> moveRows(const std::vector<JobRecord>& jobs, const ClaimDecision& decide, JobRows& rows);
// A release as a claim decides it: every job moved, as `release` says for `host`.
ClaimDecision releasing(const Release& release, const HostRecord& host);
// New jobs after the one at `lastPosition`: each inserted, its submission
// recorded, then its first steps and its change; their numbers, in order.
std::vector<JobId> addJobRows(const std::vector<NewJob>& jobs, const std::vector<std::string>& reasons,
                              double lastPosition, JobRows& rows);

class JobStore {
 public:
  virtual ~JobStore() = default;
  // Adds a queued job (last in its priority) and its submission as its first
  // transition, then its `then` steps (TransitionRefused if one is not allowed).
  virtual JobRecord addJob(const NewJob& job, std::string_view reason) = 0;
  // Several at once, in one transaction (what came in while the last one committed), in order.
  virtual std::vector<JobRecord> addJobs(const std::vector<NewJob>& jobs, const std::vector<std::string>& reasons) = 0;
  [[nodiscard]] virtual std::optional<JobRecord> job(JobId id) = 0;
  // Every job in queue order: priority (higher first), then position.
  [[nodiscard]] virtual std::vector<JobRecord> jobs() = 0;
  // The same, one at a time (a long queue is never all in memory at once).
  virtual void eachJob(const std::function<void(const JobRecord&)>& visit) = 0;
  // The jobs in these states, in queue order; the first `limit` of them, and
  // only those for `device` when one is named.
  [[nodiscard]] virtual std::vector<JobRecord> jobsIn(const std::vector<JobState>& states, size_t limit = SIZE_MAX,
                                                      const std::string& device = "") = 0;
  // Moves a job to `to` if the table allows it from the state it is in
  // (JobState.h; TransitionRefused otherwise, naming both), with `change`,
  // and records the transition, all in one transaction. A job another host
  // holds is that host's to move (TransitionRefused naming it).
  virtual JobRecord transition(JobId id, JobState to, std::string_view reason, const JobChange& change = {}) = 0;
  // Progress without a change of state (of a job this host holds; else nothing).
  virtual void update(JobId id, const JobChange& change) = 0;
  // A new place in the queue.
  virtual void reorder(JobId id, int priority, double position) = 0;
  // Another device for a job not being planned or cut (it is no longer for any device).
  virtual void setDevice(JobId id, const std::string& device) = 0;
  [[nodiscard]] virtual std::vector<Transition> transitions(JobId id) = 0;
  virtual void addEvent(std::optional<JobId> job, std::string_view kind, std::string_view text) = 0;
  [[nodiscard]] virtual std::vector<Event> events(std::optional<JobId> job, size_t newest) = 0;
  // ---- several hosts on one store ----
  // Whether other hosts may share it (PostgreSQL), or it is this daemon's alone (SQLite).
  [[nodiscard]] virtual bool shared() const = 0;
  // Registers this daemon as host `me.name` with its devices, for `lease`
  // seconds, and releases what this host held before (a restart): each job
  // as `release` says. A shared store waits up to `wait` seconds for a
  // lease the same host name still holds (a kill -9 leaves one), then
  // refuses: another daemon runs under that name. Refuses a device name
  // another live host has. Returns the jobs released.
  virtual std::vector<JobRecord> join(const HostRecord& me, const std::vector<DeviceRecord>& devices, double lease,
                                      double wait, const Release& release) = 0;
  // Renews this host's lease; false when it had run out and another host
  // released this host's jobs (it must stop what it was doing and join again).
  virtual bool heartbeat(double lease) = 0;
  // Every other host whose lease has run out: marked gone, its devices with
  // it, its jobs released as `release` says (once, by one host). The jobs.
  virtual std::vector<JobRecord> releaseLapsedHosts(const Release& release) = 0;
  [[nodiscard]] virtual std::vector<HostRecord> hosts() = 0;
  // Every host's devices, by name.
  [[nodiscard]] virtual std::vector<DeviceRecord> devices() = 0;
  // One of this host's devices, as it now is.
  virtual void putDevice(const DeviceRecord& device) = 0;
  // The jobs `query` finds, each moved as `decide` says (nullopt: left as
  // it is), in one transaction; those moved. A job moved into planning,
  // running or paused is this host's.
  virtual std::vector<JobRecord> claim(const ClaimQuery& query, const ClaimDecision& decide) = 0;

  // Leaves `request` for the host that holds its job, if another host than
  // this one holds it (in one transaction with the check); that host, or
  // nullopt when no other host holds the job (this one acts itself).
  virtual std::optional<std::string> requestAction(const ActionRequest& request) = 0;
  // The requests left for the jobs this host holds, and for jobs no host
  // holds any more (a cancel of a job whose plan ended meanwhile is still
  // carried out, by whichever host takes it), oldest first, each taken as it is read.
  virtual std::vector<ActionRequest> takeRequests() = 0;

  // The schema version of the store as opened.
  [[nodiscard]] virtual int schemaVersion() = 0;
  // Whether the engine finds the store sound ("ok"), or what it finds wrong.
  [[nodiscard]] virtual std::string integrityCheck() = 0;
};

// SQLite in WAL mode with synchronous=FULL, in `file` (created when missing),
// migrated to the newest schema. `upToVersion` stops the migrations there
// (for the tests of each one). Throws StoreError.
std::unique_ptr<JobStore> openSqliteStore(const std::filesystem::path& file,
                                          std::optional<int> upToVersion = std::nullopt);

// PostgreSQL at `uri` (postgresql://USER@HOST:PORT/DB, libpq's form), a
// store several daemons share; migrated as the SQLite one, by one daemon at a
// time. Every transaction is committed with the server's synchronous commit.
// Throws StoreError naming the URI without its password.
std::unique_ptr<JobStore> openPostgresStore(const std::string& uri, std::optional<int> upToVersion = std::nullopt);

// The URI as it may be shown: any password in it replaced by ***.
std::string uriWithoutPassword(const std::string& uri);

}  // namespace rotafab::service
