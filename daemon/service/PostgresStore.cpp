// The job store on PostgreSQL (JobStore.h), through libpq: a store several
// daemons share. Each call is one transaction at READ COMMITTED; a
// transition reads its job's row FOR UPDATE, so two hosts moving one job are
// serialized by the row's lock and the second sees what the first wrote. The
// end of the queue is read and extended under a transaction-scoped advisory
// lock, so jobs submitted through two hosts at once get distinct places. The
// server commits synchronously (its default), so a call that returned
// survives a kill of this process and of the server. The schema is the
// SQLite store's (StoreSchema.h), its version in a one-row table.

#include <fmt/format.h>
#include <libpq-fe.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "daemon/service/JobStore.h"
#include "daemon/service/StoreRows.h"
#include "daemon/service/StoreSchema.h"

namespace rotafab::service {
namespace {

// Advisory lock keys, arbitrary but fixed: for migrations, the end of the
// queue, and the hosts (one host joins, or releases a lapsed one, at a time).
constexpr const char* kMigrationLock = "SELECT pg_advisory_xact_lock(7208301)";
constexpr const char* kQueueEndLock = "SELECT pg_advisory_xact_lock(7208302)";
constexpr const char* kHostsLock = "SELECT pg_advisory_xact_lock(7208304)";
// Leases are reckoned by the server's clock, the one clock every host shares.
constexpr const char* kNow = "EXTRACT(EPOCH FROM clock_timestamp())::DOUBLE PRECISION";
constexpr const char* kHeldStates = "('planning', 'running', 'paused')";

// libpq's messages end in a newline and may run to several lines: the first, trimmed.
std::string firstLine(const char* message) {
  std::string text = message ? message : "";
  if (const size_t end = text.find('\n'); end != std::string::npos) text.resize(end);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\r')) text.pop_back();
  if (text.starts_with("ERROR:  ")) text.erase(0, 8);
  return text.empty() ? "the server gave no reason" : text;
}

// A parameter: text, or SQL NULL.
using Parameter = std::optional<std::string>;

class Result {
 public:
  explicit Result(PGresult* result) : result_(result) {}
  ~Result() { PQclear(result_); }
  Result(Result&& other) noexcept : result_(std::exchange(other.result_, nullptr)) {}
  Result& operator=(Result&& other) noexcept {
    if (this != &other) {
      PQclear(result_);
      result_ = std::exchange(other.result_, nullptr);
    }
    return *this;
  }
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;

  [[nodiscard]] int rows() const { return PQntuples(result_); }
  [[nodiscard]] bool isNull(int row, int column) const { return PQgetisnull(result_, row, column) != 0; }
  [[nodiscard]] std::string text(int row, int column) const {
    return std::string(PQgetvalue(result_, row, column), static_cast<size_t>(PQgetlength(result_, row, column)));
  }
  [[nodiscard]] int64_t integer(int row, int column) const {
    return std::strtoll(PQgetvalue(result_, row, column), nullptr, 10);
  }
  [[nodiscard]] double real(int row, int column) const {
    return std::strtod(PQgetvalue(result_, row, column), nullptr);
  }
  [[nodiscard]] const PGresult* raw() const { return result_; }

  // One row, as StoreRows.h reads it.
  struct Row {
    const Result& result;
    int index;
    [[nodiscard]] std::string text(int column) const { return result.text(index, column); }
    [[nodiscard]] int64_t integer(int column) const { return result.integer(index, column); }
    [[nodiscard]] double real(int column) const { return result.real(index, column); }
    [[nodiscard]] bool isNull(int column) const { return result.isNull(index, column); }
    [[nodiscard]] int columns() const { return PQnfields(result.result_); }
  };
  [[nodiscard]] Row row(int index) const { return {*this, index}; }

 private:
  PGresult* result_;
};

class PostgresStore final : public JobStore, private JobRows {
 public:
  PostgresStore(const std::string& uri, std::optional<int> upTo) : shown_(uriWithoutPassword(uri)) {
    // libpq takes a URI or key=value words; only the URI form is the config's.
    // A server that goes silent (a cut network) must fail a call within
    // seconds, not hold the daemon's strand for minutes: connect and TCP
    // timeouts, keepalives, and (startSession) a statement timeout. The
    // URI's own settings, read after these, take precedence.
    const char* keywords[] = {"connect_timeout",  "keepalives",       "keepalives_idle", "keepalives_interval",
                              "keepalives_count", "tcp_user_timeout", "dbname",          nullptr};
    const char* values[] = {"10", "1", "5", "2", "3", "10000", uri.c_str(), nullptr};
    connection_ = PQconnectdbParams(keywords, values, 1);
    if (!connection_ || PQstatus(connection_) != CONNECTION_OK) {
      const std::string why = connection_ ? firstLine(PQerrorMessage(connection_)) : "out of memory";
      PQfinish(connection_);
      throw StoreError(fmt::format("{}: cannot reach the job store: {}", shown_, why));
    }
    try {
      startSession();
      migrate(upTo.value_or(newestSchemaVersion()));
      version_ = schemaVersion();
      columns_ = jobColumns(version_);
    } catch (...) {
      PQfinish(connection_);
      throw;
    }
  }
  ~PostgresStore() override { PQfinish(connection_); }
  PostgresStore(const PostgresStore&) = delete;
  PostgresStore& operator=(const PostgresStore&) = delete;

  JobRecord addJob(const NewJob& job, std::string_view reason) override {
    return addJobs({job}, {std::string(reason)}).front();
  }

  std::vector<JobRecord> addJobs(const std::vector<NewJob>& jobs, const std::vector<std::string>& reasons) override {
    checkFirstSteps(jobs);
    Transaction transaction(*this);
    execute(kQueueEndLock);
    const double last = query("SELECT COALESCE(MAX(position), 0) FROM jobs").real(0, 0);
    const std::vector<JobId> ids = addJobRows(jobs, reasons, last, *this);
    transaction.commit();
    std::vector<JobRecord> added;
    for (JobId id : ids) added.push_back(*this->job(id));
    return added;
  }

  std::optional<JobRecord> job(JobId id) override {
    const Result found = query(fmt::format("SELECT {} FROM jobs WHERE id = $1", columns_), {std::to_string(id)});
    if (found.rows() == 0) return std::nullopt;
    return jobOf(found.row(0));
  }

  std::vector<JobRecord> jobs() override {
    std::vector<JobRecord> all;
    eachJob([&](const JobRecord& job) { all.push_back(job); });
    return all;
  }

  void eachJob(const std::function<void(const JobRecord&)>& visit) override {
    // A page at a time, each after the last job of the one before (keyset
    // paging), so that a long queue is never all in memory.
    constexpr int kPage = 500;
    std::optional<JobRecord> last;
    for (;;) {
      std::string after;
      std::vector<Parameter> parameters;
      if (last) {
        after = "WHERE (-priority, position, id) > ($1::BIGINT, $2::DOUBLE PRECISION, $3::BIGINT) ";
        parameters = {std::to_string(-last->priority), number(last->position), std::to_string(last->id)};
      }
      const Result page =
          query(fmt::format("SELECT {} FROM jobs {}ORDER BY -priority, position, id LIMIT {}", columns_, after, kPage),
                parameters);
      for (int row = 0; row < page.rows(); ++row) {
        last = jobOf(page.row(row));
        visit(*last);
      }
      if (page.rows() < kPage) return;
    }
  }

  std::vector<JobRecord> jobsIn(const std::vector<JobState>& states, size_t limit, const std::string& device) override {
    std::vector<Parameter> parameters;
    std::string marks;
    for (JobState state : states) {
      parameters.emplace_back(std::string(stateName(state)));
      marks += fmt::format("{}${}", marks.empty() ? "" : ", ", parameters.size());
    }
    std::string where = fmt::format("state IN ({})", marks.empty() ? "NULL" : marks);
    if (!device.empty()) {
      parameters.emplace_back(device);
      where += fmt::format(" AND device = ${}", parameters.size());
    }
    parameters.emplace_back(std::to_string(std::min<size_t>(limit, INT64_MAX)));
    const Result found = query(fmt::format("SELECT {} FROM jobs WHERE {} ORDER BY priority DESC, position LIMIT ${}",
                                           columns_, where, parameters.size()),
                               parameters);
    return jobsOf(found);
  }

  JobRecord transition(JobId id, JobState to, std::string_view reason, const JobChange& change) override {
    Transaction transaction(*this);
    const Result current =
        query(fmt::format("SELECT {} FROM jobs WHERE id = $1 FOR UPDATE", columns_), {std::to_string(id)});
    if (current.rows() == 0) throw TransitionRefused(fmt::format("there is no job {}", id));
    const JobRecord found = jobOf(current.row(0));
    checkHolder(found, host_);
    move(id, found.state, to, unixSeconds(), reason);
    apply(id, change);
    transaction.commit();
    return *job(id);
  }

  void update(JobId id, const JobChange& change) override {
    Transaction transaction(*this);
    if (version_ >= kFirstVersionWithHosts) {
      // A host whose jobs were released (its lease ran out) no longer writes to them.
      const Result holder = query("SELECT host FROM jobs WHERE id = $1 FOR UPDATE", {std::to_string(id)});
      if (holder.rows() == 0 || holder.text(0, 0) != host_) return;
    }
    apply(id, change);
    transaction.commit();
  }

  // ---- hosts ----

  bool shared() const override { return true; }

  std::vector<JobRecord> join(const HostRecord& me, const std::vector<DeviceRecord>& devices, double lease, double wait,
                              const Release& release) override {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait);
    for (;;) {
      Transaction transaction(*this);
      execute(kHostsLock);
      const Result mine =
          query(fmt::format("SELECT {}, lease_until - {} FROM hosts WHERE name = $1 FOR UPDATE", kHostColumns, kNow),
                {me.name});
      if (mine.rows() > 0 && mine.integer(0, 5) == 0 && mine.real(0, 6) > 0) {
        // The same name's lease still runs: a daemon killed a moment ago (its
        // lease runs out soon), or another daemon under this name (it renews it).
        if (std::chrono::steady_clock::now() < deadline) {
          transaction.rollback();
          std::this_thread::sleep_for(std::chrono::milliseconds(250));
          continue;
        }
        throw StoreError(fmt::format(
            "{}: another rotafabd runs as host {} on this job store (its lease is renewed); give each daemon "
            "its own name with `host:` in its configuration",
            shown_, me.name));
      }
      for (const DeviceRecord& device : devices) {
        const Result taken =
            query(fmt::format("SELECT d.host FROM devices d JOIN hosts h ON h.name = d.host "
                              "WHERE d.name = $1 AND d.host <> $2 AND h.gone = 0 AND h.lease_until > {}",
                              kNow),
                  {device.name, me.name});
        if (taken.rows() > 0) {
          throw StoreError(
              fmt::format("{}: device {} is host {}'s on this job store; give each device a name of "
                          "its own across the hosts",
                          shown_, device.name, taken.text(0, 0)));
        }
      }
      query(fmt::format("INSERT INTO hosts (name, address, started, seen, lease_until, gone) "
                        "VALUES ($1, $2, {0}, {0}, {0} + $3, 0) ON CONFLICT (name) DO UPDATE SET "
                        "address = excluded.address, started = excluded.started, seen = excluded.seen, "
                        "lease_until = excluded.lease_until, gone = 0",
                        kNow),
            {me.name, me.address, number(lease)});
      query("DELETE FROM devices WHERE host = $1", {me.name});
      for (const DeviceRecord& device : devices) {
        query(
            "INSERT INTO devices (name, host, machine, material, uri, auto_start, state, message, job) "
            "VALUES ($1, $2, $3, $4, $5, $6, $7, $8, NULL) ON CONFLICT (name) DO UPDATE SET host = excluded.host, "
            "machine = excluded.machine, material = excluded.material, uri = excluded.uri, "
            "auto_start = excluded.auto_start, state = excluded.state, message = excluded.message, job = NULL",
            {device.name, me.name, device.machine, device.material, device.uri, device.autoStart ? "1" : "0",
             device.state, device.message});
      }
      host_ = me.name;
      // What this host held before (and what a daemon before the hosts held, under no name).
      HostRecord before = me;
      if (mine.rows() > 0) before = hostOf(mine.row(0));
      const std::vector<JobId> released =
          releaseJobs(fmt::format("host IN ($1, '') AND state IN {} ORDER BY id FOR UPDATE", kHeldStates), me.name,
                      before, release);
      transaction.commit();
      return jobsNumbered(released);
    }
  }

  bool heartbeat(double lease) override {
    return query(fmt::format("UPDATE hosts SET seen = {0}, lease_until = {0} + $2 WHERE name = $1 AND gone = 0 "
                             "RETURNING 1",
                             kNow),
                 {host_, number(lease)})
               .rows() > 0;
  }

  std::vector<JobRecord> releaseLapsedHosts(const Release& release) override {
    const std::string lapsed = fmt::format("gone = 0 AND lease_until < {} AND name <> $1", kNow);
    if (query(fmt::format("SELECT 1 FROM hosts WHERE {} LIMIT 1", lapsed), {host_}).rows() == 0) return {};
    Transaction transaction(*this);
    execute(kHostsLock);  // (then read again: another host may have released them while this one waited)
    const Result hosts =
        query(fmt::format("SELECT {} FROM hosts WHERE {} ORDER BY name FOR UPDATE", kHostColumns, lapsed), {host_});
    std::vector<JobId> released;
    for (int row = 0; row < hosts.rows(); ++row) {
      const HostRecord gone = hostOf(hosts.row(row));
      query("UPDATE hosts SET gone = 1 WHERE name = $1", {gone.name});
      query("UPDATE devices SET state = 'gone', message = '', job = NULL WHERE host = $1", {gone.name});
      const std::vector<JobId> its = releaseJobs(
          fmt::format("host = $1 AND state IN {} ORDER BY id FOR UPDATE", kHeldStates), gone.name, gone, release);
      released.insert(released.end(), its.begin(), its.end());
    }
    transaction.commit();
    return jobsNumbered(released);
  }

  std::optional<std::string> requestAction(const ActionRequest& request) override {
    Transaction transaction(*this);
    const Result held = query("SELECT state, host FROM jobs WHERE id = $1 FOR UPDATE", {std::to_string(request.job)});
    if (held.rows() == 0) return std::nullopt;
    const std::string host = held.text(0, 1);
    if (!heldByAHost(stateNamed(held.text(0, 0)).value_or(JobState::Failed)) || host.empty() || host == host_) {
      return std::nullopt;
    }
    query(fmt::format("INSERT INTO requests (job, action, arguments, who, at) VALUES ($1, $2, $3, $4, {})", kNow),
          {std::to_string(request.job), request.action, request.arguments, request.who});
    transaction.commit();
    return host;
  }

  std::vector<ActionRequest> takeRequests() override {
    std::vector<ActionRequest> taken;
    if (query("SELECT 1 FROM requests LIMIT 1").rows() == 0) return taken;
    Transaction transaction(*this);
    const Result found =
        query(fmt::format("DELETE FROM requests WHERE job IN (SELECT id FROM jobs WHERE host = $1 OR host = '') "
                          "RETURNING {}",
                          kRequestColumns),
              {host_});
    for (int row = 0; row < found.rows(); ++row) taken.push_back(requestOf(found.row(row)));
    transaction.commit();
    std::sort(taken.begin(), taken.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    return taken;
  }

  std::vector<HostRecord> hosts() override {
    const Result found = query(fmt::format("SELECT {} FROM hosts ORDER BY name", kHostColumns));
    std::vector<HostRecord> all;
    for (int row = 0; row < found.rows(); ++row) all.push_back(hostOf(found.row(row)));
    return all;
  }

  std::vector<DeviceRecord> devices() override {
    const Result found = query(fmt::format("SELECT {} FROM devices ORDER BY name", kDeviceColumns));
    std::vector<DeviceRecord> all;
    for (int row = 0; row < found.rows(); ++row) all.push_back(deviceOf(found.row(row)));
    return all;
  }

  void putDevice(const DeviceRecord& device) override {
    query("UPDATE devices SET state = $1, message = $2, job = $3 WHERE name = $4 AND host = $5",
          {device.state, device.message, device.job ? Parameter(std::to_string(*device.job)) : std::nullopt,
           device.name, host_});
  }

  std::vector<JobRecord> claim(const ClaimQuery& claimed, const ClaimDecision& decide) override {
    Transaction transaction(*this);
    std::vector<Parameter> parameters{std::string(stateName(claimed.from))};
    std::string forDevice;
    if (!claimed.device.empty()) {
      parameters.emplace_back(claimed.device);
      parameters.emplace_back(claimed.machine);
      parameters.emplace_back(claimed.material);
      forDevice =
          " AND (device = $2 OR (any_device = 1 AND device IN (SELECT name FROM devices WHERE machine = $3 AND "
          "material = $4)))";
    }
    parameters.emplace_back(std::to_string(std::min<size_t>(claimed.limit, INT64_MAX)));
    // SKIP LOCKED: a job another host is claiming at this moment is passed over, not waited for.
    const Result found = query(fmt::format("SELECT {} FROM jobs WHERE state = $1{} ORDER BY priority DESC, position "
                                           "LIMIT ${} FOR UPDATE SKIP LOCKED",
                                           columns_, forDevice, parameters.size()),
                               parameters);
    const std::vector<JobId> moved = moveRows(jobsOf(found), decide, *this);
    transaction.commit();
    return jobsNumbered(moved);
  }

  void reorder(JobId id, int priority, double position) override {
    query("UPDATE jobs SET priority = $1, position = $2, updated = $3 WHERE id = $4",
          {std::to_string(priority), number(position), number(unixSeconds()), std::to_string(id)});
  }

  void setDevice(JobId id, const std::string& device) override {
    // (Only a job no host plans or cuts: one claimed meanwhile keeps its device.)
    query(
        "UPDATE jobs SET device = $1, any_device = 0, updated = $2 WHERE id = $3 AND state IN "
        "('queued', 'ready', 'interrupted', 'failed')",
        {device, number(unixSeconds()), std::to_string(id)});
  }

  std::vector<Transition> transitions(JobId id) override {
    const Result found =
        query("SELECT job, from_state, to_state, at, reason FROM transitions WHERE job = $1 ORDER BY id",
              {std::to_string(id)});
    std::vector<Transition> all;
    for (int row = 0; row < found.rows(); ++row) {
      Transition t;
      t.job = found.integer(row, 0);
      if (!found.isNull(row, 1)) t.from = stateNamed(found.text(row, 1));
      t.to = stateNamed(found.text(row, 2)).value_or(JobState::Failed);
      t.at = found.real(row, 3);
      t.reason = found.text(row, 4);
      all.push_back(std::move(t));
    }
    return all;
  }

  void addEvent(std::optional<JobId> job, std::string_view kind, std::string_view text) override {
    query("INSERT INTO events (job, at, kind, text) VALUES ($1, $2, $3, $4)",
          {job ? Parameter(std::to_string(*job)) : std::nullopt, number(unixSeconds()), std::string(kind),
           std::string(text)});
  }

  std::vector<Event> events(std::optional<JobId> job, size_t newest) override {
    const Result found =
        job ? query("SELECT id, job, at, kind, text FROM events WHERE job = $1 ORDER BY id DESC LIMIT $2",
                    {std::to_string(*job), std::to_string(newest)})
            : query("SELECT id, job, at, kind, text FROM events ORDER BY id DESC LIMIT $1", {std::to_string(newest)});
    std::vector<Event> all;
    for (int row = found.rows() - 1; row >= 0; --row) {
      Event e;
      e.id = found.integer(row, 0);
      if (!found.isNull(row, 1)) e.job = found.integer(row, 1);
      e.at = found.real(row, 2);
      e.kind = found.text(row, 3);
      e.text = found.text(row, 4);
      all.push_back(std::move(e));
    }
    return all;
  }

  int schemaVersion() override {
    const Result version = query("SELECT version FROM rotafab_schema");
    return version.rows() == 0 ? 0 : static_cast<int>(version.integer(0, 0));
  }

  std::string integrityCheck() override {
    std::string faults;
    for (const std::string& check : consistencyQueries()) {
      const Result found = query(check);
      for (int row = 0; row < found.rows(); ++row) faults += (faults.empty() ? "" : "; ") + found.text(row, 0);
    }
    return faults.empty() ? "ok" : faults;
  }

 private:
  // BEGIN ... COMMIT, rolled back unless committed. (Its BEGIN may connect
  // again; nothing within it does: a transaction cut off is lost whole.)
  class Transaction {
   public:
    explicit Transaction(PostgresStore& store) : store_(store) {
      store_.execute("BEGIN");
      store_.inTransaction_ = true;
    }
    ~Transaction() {
      store_.inTransaction_ = false;
      if (!committed_) PQclear(PQexec(store_.connection_, "ROLLBACK"));
    }
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
    void commit() {
      store_.execute("COMMIT");
      committed_ = true;
      store_.inTransaction_ = false;
    }
    void rollback() {
      PQclear(PQexec(store_.connection_, "ROLLBACK"));
      committed_ = true;
      store_.inTransaction_ = false;
    }

   private:
    PostgresStore& store_;
    bool committed_ = false;
  };

  // A double as text that reads back to the same double.
  static std::string number(double value) { return fmt::format("{}", value); }

  // The held jobs `where` finds (its $1: `host`), each moved as `release` says; their numbers.
  std::vector<JobId> releaseJobs(const std::string& where, const std::string& host, const HostRecord& before,
                                 const Release& release) {
    const Result held = query(fmt::format("SELECT {} FROM jobs WHERE {}", columns_, where), {host});
    return moveRows(jobsOf(held), releasing(release, before), *this);
  }

  static std::vector<JobRecord> jobsOf(const Result& found) {
    std::vector<JobRecord> all;
    for (int row = 0; row < found.rows(); ++row) all.push_back(jobOf(found.row(row)));
    return all;
  }

  std::vector<JobRecord> jobsNumbered(const std::vector<JobId>& ids) {
    std::vector<JobRecord> all;
    for (JobId id : ids) all.push_back(*job(id));
    return all;
  }

  // One statement with its parameters; StoreError in one line when the server refuses it.
  Result query(const std::string& sql, const std::vector<Parameter>& parameters = {}) {
    std::vector<const char*> values;
    for (const Parameter& p : parameters) values.push_back(p ? p->c_str() : nullptr);
    const auto run = [&] {
      return Result(PQexecParams(connection_, sql.c_str(), static_cast<int>(values.size()), nullptr, values.data(),
                                 nullptr, nullptr, 0));
    };
    Result result = run();
    if (connectedAgain(result)) result = run();
    check(result);
    return result;
  }

  // Statements without parameters (several, separated by semicolons, as a migration is).
  void execute(const std::string& sql) {
    Result result(PQexec(connection_, sql.c_str()));
    if (connectedAgain(result)) result = Result(PQexec(connection_, sql.c_str()));
    check(result);
  }

  // The session's settings, as every connection starts.
  void startSession() {
    // Notices (a table that exists already) are not ours to print.
    PQsetNoticeProcessor(
        connection_, [](void*, const char*) {}, nullptr);
    execute("SET client_min_messages = warning");
    execute("SET synchronous_commit = on");
    execute("SET statement_timeout = '30s'");
  }

  // When a statement outside a transaction failed because the connection
  // was lost (the server restarted, an administrator ended it), connects
  // again once, as the store was opened; true when the statement can be
  // sent again. (Sent again, a statement the server had run before the
  // connection dropped runs twice: only single statements are, an event
  // or a reorder, never a transaction.)
  bool connectedAgain(const Result& failed) {
    if (inTransaction_ || reconnecting_ || PQstatus(connection_) == CONNECTION_OK) return false;
    const PGresult* raw = failed.raw();
    if (raw && (PQresultStatus(raw) == PGRES_COMMAND_OK || PQresultStatus(raw) == PGRES_TUPLES_OK)) return false;
    PQreset(connection_);
    if (PQstatus(connection_) != CONNECTION_OK) return false;
    reconnecting_ = true;
    try {
      startSession();
    } catch (...) {
      reconnecting_ = false;
      throw;
    }
    reconnecting_ = false;
    return true;
  }

  void check(const Result& result) const {
    const PGresult* raw = result.raw();
    const ExecStatusType status = raw ? PQresultStatus(raw) : PGRES_FATAL_ERROR;
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return;
    if (PQstatus(connection_) != CONNECTION_OK) {
      throw StoreError(fmt::format("{}: the connection to the job store was lost: {}", shown_,
                                   firstLine(PQerrorMessage(connection_))));
    }
    const char* state = raw ? PQresultErrorField(raw, PG_DIAG_SQLSTATE) : nullptr;
    const std::string code = state ? state : "";
    if (code == "53100") throw StoreError(fmt::format("{}: the disk that holds the job store is full", shown_));
    throw StoreError(fmt::format("{}: the job store: {}", shown_,
                                 firstLine(raw ? PQresultErrorMessage(raw) : PQerrorMessage(connection_))));
  }

  void migrate(int upTo) {
    // Two daemons starting together on one store: one migrates, the other
    // waits for it and finds the schema new.
    Transaction transaction(*this);
    execute(kMigrationLock);
    execute("CREATE TABLE IF NOT EXISTS rotafab_schema (version INTEGER NOT NULL)");
    if (query("SELECT version FROM rotafab_schema").rows() == 0) execute("INSERT INTO rotafab_schema VALUES (0)");
    const int found = schemaVersion();
    if (found > newestSchemaVersion()) {
      throw StoreError(
          fmt::format("{}: the job store has schema version {}, made by a newer rotafabd (this one "
                      "knows up to {}); run that version on every host",
                      shown_, found, newestSchemaVersion()));
    }
    for (int version = found; version < upTo; ++version) {
      execute(migrationSql(version, StoreEngine::Postgres));
      query("UPDATE rotafab_schema SET version = $1", {std::to_string(version + 1)});
    }
    transaction.commit();
  }

  JobId insertRow(const NewJob& job, double position, double at) override {
    std::vector<Parameter> values{std::string(stateName(JobState::Queued)),
                                  std::string(kindName(job.kind)),
                                  job.source,
                                  job.owner,
                                  job.device,
                                  std::to_string(job.priority),
                                  number(position),
                                  job.options,
                                  job.spool,
                                  number(at),
                                  number(at)};
    if (version_ < kFirstVersionWithHosts) {
      return query(
                 "INSERT INTO jobs (state, kind, source, owner, device, priority, position, options, spool, "
                 "submitted, updated) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11) RETURNING id",
                 values)
          .integer(0, 0);
    }
    values.emplace_back(job.device.empty() ? "1" : "0");
    return query(
               "INSERT INTO jobs (state, kind, source, owner, device, priority, position, options, spool, "
               "submitted, updated, any_device) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12) "
               "RETURNING id",
               values)
        .integer(0, 0);
  }

  void apply(JobId id, const JobChange& change) override {
    const auto numberOf = [](const auto& value) -> Parameter {
      return value ? Parameter(std::to_string(*value)) : std::nullopt;
    };
    if (!change.device && !change.summary && !change.sheets && !change.sheet && !change.stroke && !change.strokes)
      return;
    // One statement, each column kept where its change is unset (NULL): one round trip, not one per column.
    query(
        "UPDATE jobs SET device = COALESCE($1, device), summary = COALESCE($2, summary), sheets = COALESCE($3::BIGINT, "
        "sheets), sheet = COALESCE($4::BIGINT, sheet), stroke = COALESCE($5::BIGINT, stroke), strokes = "
        "COALESCE($6::BIGINT, strokes) WHERE id = $7",
        {change.device, change.summary, numberOf(change.sheets), numberOf(change.sheet), numberOf(change.stroke),
         numberOf(change.strokes), std::to_string(id)});
  }

  void move(JobId id, JobState from, JobState to, double at, std::string_view reason) override {
    if (!allowedTransition(from, to)) {
      throw TransitionRefused(fmt::format("job {} is {}; it cannot become {}", id, stateName(from), stateName(to)));
    }
    if (version_ >= kFirstVersionWithHosts) {
      query("UPDATE jobs SET state = $1, message = $2, updated = $3, host = $4 WHERE id = $5",
            {std::string(stateName(to)), std::string(reason), number(at), heldByAHost(to) ? host_ : std::string(),
             std::to_string(id)});
    } else {
      query("UPDATE jobs SET state = $1, message = $2, updated = $3 WHERE id = $4",
            {std::string(stateName(to)), std::string(reason), number(at), std::to_string(id)});
    }
    record(id, from, to, at, reason);
  }

  void record(JobId id, std::optional<JobState> from, JobState to, double at, std::string_view reason) override {
    query("INSERT INTO transitions (job, from_state, to_state, at, reason) VALUES ($1, $2, $3, $4, $5)",
          {std::to_string(id), from ? Parameter(std::string(stateName(*from))) : std::nullopt,
           std::string(stateName(to)), number(at), std::string(reason)});
  }

  std::string shown_;
  PGconn* connection_ = nullptr;
  int version_ = 0;
  std::string columns_;  // a job's (jobColumns())
  std::string host_;     // this daemon's, once it joined
  bool inTransaction_ = false, reconnecting_ = false;
};

}  // namespace

std::unique_ptr<JobStore> openPostgresStore(const std::string& uri, std::optional<int> upToVersion) {
  return std::make_unique<PostgresStore>(uri, upToVersion);
}

std::string uriWithoutPassword(const std::string& uri) {
  // postgresql://USER:PASSWORD@HOST...: the password is between the first ':' after the scheme and the '@'.
  const size_t scheme = uri.find("://");
  if (scheme == std::string::npos) return uri;
  const size_t at = uri.find('@', scheme + 3);
  if (at == std::string::npos) return uri;
  const size_t colon = uri.find(':', scheme + 3);
  if (colon == std::string::npos || colon > at) return uri;
  return uri.substr(0, colon + 1) + "***" + uri.substr(at);
}

}  // namespace rotafab::service
