// The job store on SQLite (JobStore.h). WAL mode, so that readers never
// wait for a writer; synchronous=FULL, so that a transaction that returned
// survives a power cut, not only a kill of the process (in WAL mode NORMAL
// would only survive the kill). The schema is versioned in `user_version`
// and migrated one step at a time, each step a transaction of its own.

#include <fmt/format.h>
#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>

#include "daemon/service/JobStore.h"
#include "daemon/service/StoreRows.h"
#include "daemon/service/StoreSchema.h"

namespace rotafab::service {
namespace {

// The store's statements, each prepared once: preparing took more of a
// submission's time on the store than the insert it prepared.
class StatementCache {
 public:
  explicit StatementCache(sqlite3* db) : db_(db) {}
  ~StatementCache() {
    for (const auto& [sql, kept] : prepared_) sqlite3_finalize(kept.statement);
  }
  StatementCache(const StatementCache&) = delete;
  StatementCache& operator=(const StatementCache&) = delete;

  struct Kept {
    sqlite3_stmt* statement = nullptr;
    bool inUse = false;
  };
  // The prepared statement for `sql`, lent until giveBack(); null when it
  // is lent already (a visit that queries again), and the caller prepares
  // one of its own.
  Kept* take(const std::string& sql) {
    Kept& kept = prepared_[sql];
    if (kept.inUse) return nullptr;
    if (!kept.statement &&
        sqlite3_prepare_v3(db_, sql.c_str(), -1, SQLITE_PREPARE_PERSISTENT, &kept.statement, nullptr) != SQLITE_OK)
      return nullptr;
    kept.inUse = true;
    return &kept;  // (an unordered_map's values stay where they are)
  }
  static void giveBack(Kept& kept) {
    sqlite3_reset(kept.statement);
    sqlite3_clear_bindings(kept.statement);
    kept.inUse = false;
  }
  sqlite3* db() const { return db_; }

 private:
  sqlite3* db_;
  std::unordered_map<std::string, Kept> prepared_;
};

class Statement {
 public:
  Statement(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &statement_, nullptr) != SQLITE_OK) fail("prepare");
  }
  Statement(StatementCache& cache, const std::string& sql) : db_(cache.db()), lent_(cache.take(sql)) {
    if (lent_) {
      statement_ = lent_->statement;
    } else if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement_, nullptr) != SQLITE_OK) {
      fail("prepare");
    }
  }
  ~Statement() {
    if (lent_) {
      StatementCache::giveBack(*lent_);
    } else {
      sqlite3_finalize(statement_);
    }
  }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, int64_t value) {
    check(sqlite3_bind_int64(statement_, index, value));
    return *this;
  }
  Statement& bind(int index, double value) {
    check(sqlite3_bind_double(statement_, index, value));
    return *this;
  }
  Statement& bind(int index, std::string_view text) {
    check(sqlite3_bind_text(statement_, index, text.data(), static_cast<int>(text.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& bindNull(int index) {
    check(sqlite3_bind_null(statement_, index));
    return *this;
  }
  // True while there is a row.
  bool step() {
    const int result = sqlite3_step(statement_);
    if (result == SQLITE_ROW) return true;
    if (result == SQLITE_DONE) return false;
    fail("step");
  }
  int64_t integer(int column) const { return sqlite3_column_int64(statement_, column); }
  int columns() const { return sqlite3_column_count(statement_); }
  double real(int column) const { return sqlite3_column_double(statement_, column); }
  void reset() { sqlite3_reset(statement_); }
  bool isNull(int column) const { return sqlite3_column_type(statement_, column) == SQLITE_NULL; }
  std::string text(int column) const {
    const auto* bytes = reinterpret_cast<const char*>(sqlite3_column_text(statement_, column));
    return bytes ? std::string(bytes, static_cast<size_t>(sqlite3_column_bytes(statement_, column))) : std::string();
  }

 private:
  void check(int result) const {
    if (result != SQLITE_OK) fail("bind");
  }
  [[noreturn]] void fail(const char* what) const;

  sqlite3* db_;
  sqlite3_stmt* statement_ = nullptr;
  StatementCache::Kept* lent_ = nullptr;  // the cache's, given back when done; else finalized
};

// One line for what SQLite said, in the words of what the daemon was doing.
[[noreturn]] void storeFailure(sqlite3* db, std::string_view doing) {
  const int code = sqlite3_extended_errcode(db) & 0xff;
  if (code == SQLITE_FULL) throw StoreError(fmt::format("{}: the disk that holds the job store is full", doing));
  if (code == SQLITE_NOTADB || code == SQLITE_CORRUPT)
    throw StoreError(fmt::format("{}: the job store is not a sound SQLite database ({})", doing, sqlite3_errmsg(db)));
  throw StoreError(fmt::format("{}: {}", doing, sqlite3_errmsg(db)));
}

void Statement::fail(const char* what) const { storeFailure(db_, fmt::format("the job store ({})", what)); }

void execute(sqlite3* db, const char* sql, std::string_view doing) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
    sqlite3_free(error);
    storeFailure(db, doing);
  }
}

// BEGIN IMMEDIATE ... COMMIT, rolled back unless committed.
class Transaction {
 public:
  explicit Transaction(sqlite3* db) : db_(db) { execute(db_, "BEGIN IMMEDIATE", "the job store (begin)"); }
  ~Transaction() {
    if (!committed_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  void commit() {
    execute(db_, "COMMIT", "the job store (commit)");
    committed_ = true;
  }

 private:
  sqlite3* db_;
  bool committed_ = false;
};

// The jobs for a device (its name, then its machine's): those submitted for
// it, and those for any device that were planned for a device of its machine.
constexpr const char* kForTheDevice =
    " AND (device = ? OR (any_device = 1 AND device IN (SELECT name FROM devices WHERE machine = ? AND material = "
    "?)))";

class SqliteStore final : public JobStore, private JobRows {
 public:
  SqliteStore(const std::filesystem::path& file, std::optional<int> upTo) : file_(file) {
    const int opened = sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
    if (opened != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw StoreError(fmt::format("{}: cannot open the job store: {}", file.string(), why));
    }
    try {
      sqlite3_busy_timeout(db_, 5000);
      sqlite3_extended_result_codes(db_, 1);
      execute(db_, "PRAGMA journal_mode=WAL", doing("set WAL mode").c_str());
      execute(db_, "PRAGMA synchronous=FULL", doing("set synchronous=FULL").c_str());
      execute(db_, "PRAGMA foreign_keys=ON", doing("turn on foreign keys").c_str());
      migrate(upTo.value_or(newestSchemaVersion()));
      version_ = schemaVersion();
      columns_ = jobColumns(version_);
      statements_.emplace(db_);
    } catch (...) {
      sqlite3_close(db_);
      throw;
    }
  }
  ~SqliteStore() override {
    statements_.reset();  // finalized before the database closes
    sqlite3_close(db_);
  }

  JobRecord addJob(const NewJob& job, std::string_view reason) override {
    return addJobs({job}, {std::string(reason)}).front();
  }

  std::vector<JobRecord> addJobs(const std::vector<NewJob>& jobs, const std::vector<std::string>& reasons) override {
    checkFirstSteps(jobs);
    Transaction transaction(db_);
    Statement last(*statements_, "SELECT COALESCE(MAX(position), 0) FROM jobs");
    last.step();
    const std::vector<JobId> ids = addJobRows(jobs, reasons, last.real(0), *this);
    transaction.commit();
    std::vector<JobRecord> added;
    for (JobId id : ids) added.push_back(*this->job(id));
    return added;
  }

  std::optional<JobRecord> job(JobId id) override {
    Statement select(*statements_, fmt::format("SELECT {} FROM jobs WHERE id = ?", columns_));
    select.bind(1, id);
    if (!select.step()) return std::nullopt;
    return jobOf(select);
  }

  std::vector<JobRecord> jobs() override {
    std::vector<JobRecord> all;
    eachJob([&](const JobRecord& job) { all.push_back(job); });
    return all;
  }

  void eachJob(const std::function<void(const JobRecord&)>& visit) override {
    Statement select(*statements_, fmt::format("SELECT {} FROM jobs ORDER BY priority DESC, position", columns_));
    while (select.step()) visit(jobOf(select));
  }

  std::vector<JobRecord> jobsIn(const std::vector<JobState>& states, size_t limit, const std::string& device) override {
    std::string marks;
    for (size_t i = 0; i < states.size(); ++i) marks += i == 0 ? "?" : ", ?";
    Statement select(*statements_,
                     fmt::format("SELECT {} FROM jobs WHERE state IN ({}){} ORDER BY priority DESC, position "
                                 "LIMIT ?",
                                 columns_, marks, device.empty() ? "" : " AND device = ?"));
    int index = 1;
    for (JobState state : states) select.bind(index++, stateName(state));
    if (!device.empty()) select.bind(index++, device);
    select.bind(index, static_cast<int64_t>(std::min<size_t>(limit, INT64_MAX)));
    std::vector<JobRecord> found;
    while (select.step()) found.push_back(jobOf(select));
    return found;
  }

  JobRecord transition(JobId id, JobState to, std::string_view reason, const JobChange& change) override {
    Transaction transaction(db_);
    const auto current = job(id);
    if (!current) throw TransitionRefused(fmt::format("there is no job {}", id));
    checkHolder(*current, host_);
    move(id, current->state, to, unixSeconds(), reason);
    apply(id, change);
    transaction.commit();
    return *job(id);
  }

  void update(JobId id, const JobChange& change) override {
    Transaction transaction(db_);
    apply(id, change);
    transaction.commit();
  }

  // ---- hosts: one, this daemon (the store is in its state directory) ----

  bool shared() const override { return false; }

  std::vector<JobRecord> join(const HostRecord& me, const std::vector<DeviceRecord>& devices, double lease, double,
                              const Release& release) override {
    Transaction transaction(db_);
    const double now = unixSeconds();
    execute(db_, "DELETE FROM devices", doing("forget the devices").c_str());
    {
      Statement others(*statements_, "DELETE FROM hosts WHERE name <> ?");
      others.bind(1, me.name);
      others.step();
      Statement upsert(*statements_,
                       "INSERT INTO hosts (name, address, started, seen, lease_until, gone) VALUES (?, ?, ?, ?, ?, 0) "
                       "ON CONFLICT (name) DO UPDATE SET address = excluded.address, started = excluded.started, "
                       "seen = excluded.seen, lease_until = excluded.lease_until, gone = 0");
      upsert.bind(1, me.name).bind(2, me.address).bind(3, now).bind(4, now).bind(5, now + lease);
      upsert.step();
    }
    for (const DeviceRecord& device : devices) insertDevice(device, me.name);
    host_ = me.name;
    // Whatever any host held before is this one's to release: it alone uses the store.
    std::vector<JobRecord> held;
    {
      Statement select(*statements_, fmt::format("SELECT {} FROM jobs WHERE state IN ('planning', 'running', "
                                                 "'paused') ORDER BY id",
                                                 columns_));
      while (select.step()) held.push_back(jobOf(select));
    }
    const std::vector<JobId> released = moveRows(held, releasing(release, me), *this);
    transaction.commit();
    return jobsNumbered(released);
  }

  // Nothing to renew: no other host could take this one's jobs (and a
  // synced write every few seconds would cost for nothing).
  bool heartbeat(double) override { return true; }
  std::vector<JobRecord> releaseLapsedHosts(const Release&) override { return {}; }

  std::optional<std::string> requestAction(const ActionRequest& request) override {
    Transaction transaction(db_);
    const auto held = job(request.job);
    if (!held || !heldByAHost(held->state) || held->host.empty() || held->host == host_) return std::nullopt;
    Statement insert(*statements_, "INSERT INTO requests (job, action, arguments, who, at) VALUES (?, ?, ?, ?, ?)");
    insert.bind(1, request.job).bind(2, request.action).bind(3, request.arguments).bind(4, request.who);
    insert.bind(5, unixSeconds());
    insert.step();
    transaction.commit();
    return held->host;
  }

  std::vector<ActionRequest> takeRequests() override {
    std::vector<ActionRequest> taken;
    Statement any(*statements_, "SELECT 1 FROM requests LIMIT 1");
    if (!any.step()) return taken;
    any.reset();
    Transaction transaction(db_);
    {
      Statement take(*statements_, fmt::format("DELETE FROM requests WHERE job IN (SELECT id FROM jobs WHERE host = ? "
                                               "OR host = '') RETURNING {}",
                                               kRequestColumns));
      take.bind(1, host_);
      while (take.step()) taken.push_back(requestOf(take));
    }
    transaction.commit();
    std::sort(taken.begin(), taken.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    return taken;
  }

  std::vector<JobRecord> jobsNumbered(const std::vector<JobId>& ids) {
    std::vector<JobRecord> all;
    for (JobId id : ids) all.push_back(*job(id));
    return all;
  }

  std::vector<HostRecord> hosts() override {
    Statement select(*statements_, fmt::format("SELECT {} FROM hosts ORDER BY name", kHostColumns));
    std::vector<HostRecord> all;
    while (select.step()) all.push_back(hostOf(select));
    return all;
  }

  std::vector<DeviceRecord> devices() override {
    Statement select(*statements_, fmt::format("SELECT {} FROM devices ORDER BY name", kDeviceColumns));
    std::vector<DeviceRecord> all;
    while (select.step()) all.push_back(deviceOf(select));
    return all;
  }

  void putDevice(const DeviceRecord& device) override {
    Transaction transaction(db_);
    Statement set(*statements_, "UPDATE devices SET state = ?, message = ?, job = ? WHERE name = ? AND host = ?");
    set.bind(1, device.state).bind(2, device.message);
    if (device.job) {
      set.bind(3, *device.job);
    } else {
      set.bindNull(3);
    }
    set.bind(4, device.name).bind(5, host_);
    set.step();
    transaction.commit();
  }

  std::vector<JobRecord> claim(const ClaimQuery& query, const ClaimDecision& decide) override {
    Transaction transaction(db_);
    std::vector<JobRecord> found;
    {
      Statement select(*statements_,
                       fmt::format("SELECT {} FROM jobs WHERE state = ?{} ORDER BY priority DESC, position LIMIT ?",
                                   columns_, query.device.empty() ? "" : kForTheDevice));
      int index = 1;
      select.bind(index++, stateName(query.from));
      if (!query.device.empty()) {
        select.bind(index, query.device).bind(index + 1, query.machine).bind(index + 2, query.material);
        index += 3;
      }
      select.bind(index, static_cast<int64_t>(std::min<size_t>(query.limit, INT64_MAX)));
      while (select.step()) found.push_back(jobOf(select));
    }
    const std::vector<JobId> moved = moveRows(found, decide, *this);
    transaction.commit();
    return jobsNumbered(moved);
  }

  void reorder(JobId id, int priority, double position) override {
    Transaction transaction(db_);
    Statement set(*statements_, "UPDATE jobs SET priority = ?, position = ?, updated = ? WHERE id = ?");
    set.bind(1, static_cast<int64_t>(priority)).bind(2, position).bind(3, unixSeconds()).bind(4, id);
    set.step();
    transaction.commit();
  }

  void setDevice(JobId id, const std::string& device) override {
    Transaction transaction(db_);
    // (Only a job no host plans or cuts: one claimed meanwhile keeps its device.)
    Statement set(*statements_,
                  "UPDATE jobs SET device = ?, any_device = 0, updated = ? WHERE id = ? AND state IN "
                  "('queued', 'ready', 'interrupted', 'failed')");
    set.bind(1, device).bind(2, unixSeconds()).bind(3, id);
    set.step();
    transaction.commit();
  }

  std::vector<Transition> transitions(JobId id) override {
    Statement select(*statements_,
                     "SELECT job, from_state, to_state, at, reason FROM transitions WHERE job = ? ORDER BY id");
    select.bind(1, id);
    std::vector<Transition> all;
    while (select.step()) {
      Transition t;
      t.job = select.integer(0);
      if (!select.isNull(1)) t.from = stateNamed(select.text(1));
      t.to = stateNamed(select.text(2)).value_or(JobState::Failed);
      t.at = select.real(3);
      t.reason = select.text(4);
      all.push_back(std::move(t));
    }
    return all;
  }

  void addEvent(std::optional<JobId> job, std::string_view kind, std::string_view text) override {
    Statement insert(*statements_, "INSERT INTO events (job, at, kind, text) VALUES (?, ?, ?, ?)");
    if (job) {
      insert.bind(1, *job);
    } else {
      insert.bindNull(1);
    }
    insert.bind(2, unixSeconds()).bind(3, kind).bind(4, text);
    insert.step();
  }

  std::vector<Event> events(std::optional<JobId> job, size_t newest) override {
    Statement select(*statements_,
                     job ? "SELECT id, job, at, kind, text FROM events WHERE job = ? ORDER BY id DESC LIMIT ?"
                         : "SELECT id, job, at, kind, text FROM events ORDER BY id DESC LIMIT ?");
    int index = 1;
    if (job) select.bind(index++, *job);
    select.bind(index, static_cast<int64_t>(newest));
    std::vector<Event> all;
    while (select.step()) {
      Event e;
      e.id = select.integer(0);
      if (!select.isNull(1)) e.job = select.integer(1);
      e.at = select.real(2);
      e.kind = select.text(3);
      e.text = select.text(4);
      all.insert(all.begin(), std::move(e));
    }
    return all;
  }

  int schemaVersion() override {
    Statement version(db_, "PRAGMA user_version");
    version.step();
    return static_cast<int>(version.integer(0));
  }

  std::string integrityCheck() override {
    Statement check(db_, "PRAGMA integrity_check");
    std::string result;
    while (check.step()) result += (result.empty() ? "" : "; ") + check.text(0);
    if (result != "ok") return result;
    result.clear();
    for (const std::string& query : consistencyQueries()) {
      Statement faults(db_, query.c_str());
      while (faults.step()) result += (result.empty() ? "" : "; ") + faults.text(0);
    }
    return result.empty() ? "ok" : result;
  }

 private:
  std::string doing(std::string_view what) const { return fmt::format("{}: {}", file_.string(), what); }

  void migrate(int upTo) {
    const int found = schemaVersion();
    if (found > newestSchemaVersion()) {
      throw StoreError(
          fmt::format("{}: the job store has schema version {}, made by a newer rotafabd (this one "
                      "knows up to {}); run that version, or give this one another state directory",
                      file_.string(), found, newestSchemaVersion()));
    }
    for (int version = found; version < upTo; ++version) {
      Transaction transaction(db_);
      execute(db_, migrationSql(version, StoreEngine::Sqlite).c_str(),
              doing(fmt::format("migrate the schema to version {}", version + 1)).c_str());
      execute(db_, fmt::format("PRAGMA user_version = {}", version + 1).c_str(),
              doing("record the schema version").c_str());
      transaction.commit();
    }
  }

  void insertDevice(const DeviceRecord& device, const std::string& host) {
    Statement insert(*statements_,
                     "INSERT INTO devices (name, host, machine, material, uri, auto_start, state, message, job) "
                     "VALUES (?, ?, ?, ?, ?, ?, ?, ?, NULL)");
    insert.bind(1, device.name)
        .bind(2, host)
        .bind(3, device.machine)
        .bind(4, device.material)
        .bind(5, device.uri)
        .bind(6, static_cast<int64_t>(device.autoStart))
        .bind(7, device.state)
        .bind(8, device.message);
    insert.step();
  }

  JobId insertRow(const NewJob& job, double position, double at) override {
    Statement insert(*statements_,
                     version_ >= kFirstVersionWithHosts
                         ? "INSERT INTO jobs (state, kind, source, owner, device, priority, position, options, spool, "
                           "submitted, updated, any_device) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"
                         : "INSERT INTO jobs (state, kind, source, owner, device, priority, position, options, spool, "
                           "submitted, updated) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    if (version_ >= kFirstVersionWithHosts) insert.bind(12, static_cast<int64_t>(job.device.empty()));
    insert.bind(1, stateName(JobState::Queued))
        .bind(2, kindName(job.kind))
        .bind(3, job.source)
        .bind(4, job.owner)
        .bind(5, job.device)
        .bind(6, static_cast<int64_t>(job.priority))
        .bind(7, position)
        .bind(8, job.options)
        .bind(9, job.spool)
        .bind(10, at)
        .bind(11, at);
    insert.step();
    return static_cast<JobId>(sqlite3_last_insert_rowid(db_));
  }

  void apply(JobId id, const JobChange& change) override {
    const auto setText = [&](const char* column, const std::optional<std::string>& value) {
      if (!value) return;
      Statement set(*statements_, fmt::format("UPDATE jobs SET {} = ? WHERE id = ?", column));
      set.bind(1, *value).bind(2, id);
      set.step();
    };
    const auto setNumber = [&](const char* column, std::optional<int64_t> value) {
      if (!value) return;
      Statement set(*statements_, fmt::format("UPDATE jobs SET {} = ? WHERE id = ?", column));
      set.bind(1, *value).bind(2, id);
      set.step();
    };
    setText("device", change.device);
    setText("summary", change.summary);
    setNumber("sheets", change.sheets);
    setNumber("sheet", change.sheet);
    setNumber("stroke", change.stroke);
    setNumber("strokes", change.strokes);
  }

  // The job's state and message, and the transition's record; in the caller's transaction.
  void move(JobId id, JobState from, JobState to, double at, std::string_view reason) override {
    if (!allowedTransition(from, to)) {
      throw TransitionRefused(fmt::format("job {} is {}; it cannot become {}", id, stateName(from), stateName(to)));
    }
    if (version_ >= kFirstVersionWithHosts) {
      Statement set(*statements_, "UPDATE jobs SET state = ?, message = ?, updated = ?, host = ? WHERE id = ?");
      set.bind(1, stateName(to)).bind(2, reason).bind(3, at).bind(4, heldByAHost(to) ? host_ : "").bind(5, id);
      set.step();
    } else {
      Statement set(*statements_, "UPDATE jobs SET state = ?, message = ?, updated = ? WHERE id = ?");
      set.bind(1, stateName(to)).bind(2, reason).bind(3, at).bind(4, id);
      set.step();
    }
    record(id, from, to, at, reason);
  }

  void record(JobId id, std::optional<JobState> from, JobState to, double at, std::string_view reason) override {
    Statement insert(*statements_,
                     "INSERT INTO transitions (job, from_state, to_state, at, reason) VALUES (?, ?, ?, ?, ?)");
    insert.bind(1, id);
    if (from) {
      insert.bind(2, stateName(*from));
    } else {
      insert.bindNull(2);
    }
    insert.bind(3, stateName(to)).bind(4, at).bind(5, reason);
    insert.step();
  }

  std::filesystem::path file_;
  int version_ = 0;
  std::string columns_;  // a job's (jobColumns())
  std::string host_;     // this daemon's, once it joined
  sqlite3* db_ = nullptr;
  std::optional<StatementCache> statements_;
};

}  // namespace

std::unique_ptr<JobStore> openSqliteStore(const std::filesystem::path& file, std::optional<int> upToVersion) {
  return std::make_unique<SqliteStore>(file, upToVersion);
}

}  // namespace rotafab::service
