// The job store (daemon/service/JobStore.h) on both engines, a real SQLite
// file and a real PostgreSQL server: the table of transitions enforced and
// every move recorded, the queue's order, what survives closing the store,
// and the schema migrated from its first version up.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fmt/format.h>

#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>

#include "daemon/service/JobStore.h"
#include "support/TestDatabase.h"
#include "support/TestSupport.h"

namespace rotafab::service {
namespace {

using test::TempDir;

NewJob meshJob(const std::string& source, int priority = 0) {
  NewJob job;
  job.source = source;
  job.owner = "alice";
  job.device = "laser1";
  job.priority = priority;
  job.options = R"(["--structure","band"])";
  job.spool = "job-" + source;
  return job;
}

// Each test on each engine: a new, empty store, opened again as often as the test asks.
class Stores : public ::testing::TestWithParam<StoreEngine> {
 protected:
  // The store made last (a new one with fresh()), opened; migrated up to `upTo`.
  std::unique_ptr<JobStore> open(std::optional<int> upTo = std::nullopt) {
    if (!made_) fresh();
    if (GetParam() == StoreEngine::Sqlite) return openSqliteStore(file(), upTo);
    return openPostgresStore(databases_.back()->uri(), upTo);
  }
  // A new store to open, with nothing in it.
  void fresh() {
    made_ = true;
    ++count_;
    if (GetParam() == StoreEngine::Postgres) databases_.push_back(std::make_unique<test::TestDatabase>());
  }
  [[nodiscard]] std::filesystem::path file() const {
    return dir_.path() / ("jobs-" + std::to_string(count_) + ".sqlite3");
  }
  // SQL on the store made last, outside the store.
  void sql(const std::string& statement);

 private:
  TempDir dir_;
  std::vector<std::unique_ptr<test::TestDatabase>> databases_;
  bool made_ = false;
  int count_ = 0;
};

}  // namespace

// How a test's name shows its engine (ctest's list: "... # GetParam() = Postgres").
void PrintTo(StoreEngine engine, std::ostream* out) { *out << (engine == StoreEngine::Sqlite ? "Sqlite" : "Postgres"); }

namespace {

INSTANTIATE_TEST_SUITE_P(Engines, Stores, ::testing::Values(StoreEngine::Sqlite, StoreEngine::Postgres),
                         [](const auto& info) { return info.param == StoreEngine::Sqlite ? "Sqlite" : "Postgres"; });

void sql(const std::filesystem::path& file, const std::string& statement) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, statement.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

void Stores::sql(const std::string& statement) {
  if (GetParam() == StoreEngine::Sqlite) {
    service::sql(file(), statement);
  } else {
    test::serverSql(statement, databases_.back()->uri());
  }
}

TEST_P(Stores, TheTableOfTransitionsIsEnforcedAndEveryMoveRecorded) {
  auto store = open();
  const JobRecord job = store->addJob(meshJob("cube.obj"), "submitted by alice");
  EXPECT_EQ(job.state, JobState::Queued);
  // A queued job cannot be cut before it is planned.
  EXPECT_THROW(store->transition(job.id, JobState::Running, "start"), TransitionRefused);
  try {
    store->transition(job.id, JobState::Done, "done");
    FAIL();
  } catch (const TransitionRefused& refused) {
    EXPECT_STREQ(refused.what(), "job 1 is queued; it cannot become done");
  }
  store->transition(job.id, JobState::Planning, "planning");
  JobChange planned;
  planned.sheets = 3;
  planned.summary = R"({"sheets":3})";
  EXPECT_EQ(store->transition(job.id, JobState::Ready, "planned", planned).sheets, 3);
  store->transition(job.id, JobState::Running, "started by bob");
  store->transition(job.id, JobState::Interrupted, "the daemon stopped");
  // Only an explicit resume brings an interrupted job back; a done one stays done.
  store->transition(job.id, JobState::Running, "resumed from sheet 2");
  store->transition(job.id, JobState::Done, "cut");
  for (JobState next : allStates()) {
    EXPECT_THROW(store->transition(job.id, next, "again"), TransitionRefused) << stateName(next);
  }
  const auto history = store->transitions(job.id);
  ASSERT_EQ(history.size(), 7u);
  EXPECT_FALSE(history[0].from.has_value());
  EXPECT_EQ(history[0].reason, "submitted by alice");
  EXPECT_EQ(history[3].to, JobState::Running);
  EXPECT_EQ(history[3].reason, "started by bob");
  EXPECT_EQ(*history[6].from, JobState::Running);
  EXPECT_EQ(store->job(job.id)->message, "cut");
  EXPECT_THROW(store->transition(99, JobState::Planning, "x"), TransitionRefused);
}

TEST_P(Stores, AJobsFirstStepsAreRecordedWithItsSubmissionOrNotAtAll) {
  auto store = open();
  store->addJob(meshJob("first"), "submitted by alice");
  // A planned folder checked while it was submitted: queued, planning and ready in one commit.
  NewJob planned = meshJob("soccer");
  planned.kind = JobKind::Planned;
  planned.then = {
      {JobState::Planning, [](JobId) { return std::string("planning against laser1"); }},
      {JobState::Ready, [](JobId id) { return "planned; start it with `rotafab start " + std::to_string(id) + "`"; }}};
  planned.change.sheets = 3;
  const auto added = store->addJobs({planned, meshJob("third")}, {"submitted by bob", "submitted by carol"});
  ASSERT_EQ(added.size(), 2u);
  EXPECT_EQ(added[0].state, JobState::Ready);
  EXPECT_EQ(added[0].sheets, 3);
  EXPECT_EQ(added[0].message, "planned; start it with `rotafab start 2`");
  EXPECT_EQ(added[1].state, JobState::Queued);
  EXPECT_EQ(added[1].sheets, 0);
  const auto history = store->transitions(added[0].id);
  ASSERT_EQ(history.size(), 3u);
  EXPECT_FALSE(history[0].from.has_value());
  EXPECT_EQ(history[0].reason, "submitted by bob");
  EXPECT_EQ(*history[1].from, JobState::Queued);
  EXPECT_EQ(history[1].to, JobState::Planning);
  EXPECT_EQ(*history[2].from, JobState::Planning);
  EXPECT_EQ(history[2].to, JobState::Ready);
  // A step the table refuses (a queued job cannot be cut) refuses the whole group: no job of it is added.
  NewJob cut = meshJob("cut");
  cut.then = {{JobState::Running, [](JobId) { return std::string("cut at once"); }}};
  EXPECT_THROW(store->addJobs({meshJob("fourth"), cut}, {"s", "s"}), TransitionRefused);
  EXPECT_EQ(store->jobs().size(), 3u);
  EXPECT_EQ(store->addJob(meshJob("fifth"), "s").id, 4);
}

TEST(JobStore, FinalStatesAreFinalAndOnlyRunningOrPausedJobsHoldADevice) {
  for (JobState from : allStates()) {
    for (JobState to : allStates()) {
      if (from == JobState::Done || from == JobState::Cancelled) {
        EXPECT_FALSE(allowedTransition(from, to));
      }
      // Nothing goes back to queued but a plan the daemon's stop broke off, or a
      // planned job moved to a device of another machine, to be planned for it.
      if (to == JobState::Queued) {
        EXPECT_EQ(allowedTransition(from, to), from == JobState::Planning || from == JobState::Ready);
      }
      // A cut starts only from a job that is ready, paused, interrupted or failed (each by an operator).
      if (to == JobState::Running) {
        EXPECT_EQ(allowedTransition(from, to), from == JobState::Ready || from == JobState::Paused ||
                                                   from == JobState::Interrupted || from == JobState::Failed)
            << stateName(from);
      }
    }
    EXPECT_EQ(holdsDevice(from), from == JobState::Running || from == JobState::Paused);
    EXPECT_EQ(stateNamed(stateName(from)), from);
  }
}

TEST_P(Stores, TheQueueIsInPriorityThenSubmissionOrderAndCanBeReordered) {
  auto store = open();
  const JobId a = store->addJob(meshJob("a"), "s").id;
  const JobId b = store->addJob(meshJob("b"), "s").id;
  const JobId c = store->addJob(meshJob("c", 5), "s").id;
  auto order = [&] {
    std::vector<JobId> ids;
    for (const JobRecord& job : store->jobs()) ids.push_back(job.id);
    return ids;
  };
  EXPECT_EQ(order(), (std::vector<JobId>{c, a, b}));
  const JobRecord first = *store->job(a);
  store->reorder(b, first.priority, first.position - 0.5);
  EXPECT_EQ(order(), (std::vector<JobId>{c, b, a}));
  store->reorder(a, 9, first.position);
  EXPECT_EQ(order(), (std::vector<JobId>{a, c, b}));
  // The scheduler's question: which jobs are queued (or ready), in queue order.
  store->transition(c, JobState::Planning, "planning");
  const auto queued = store->jobsIn({JobState::Queued});
  ASSERT_EQ(queued.size(), 2u);
  EXPECT_EQ(queued[0].id, a);
  EXPECT_EQ(queued[1].id, b);
  EXPECT_EQ(store->jobsIn({JobState::Planning, JobState::Ready}).size(), 1u);
}

// The store's statements are prepared once and kept: a visit that asks the
// store again, even the same question, gets answers of its own; a new job
// goes after the last one, wherever a reorder put it.
TEST_P(Stores, AVisitMayQueryTheStoreAgainAndANewJobGoesLast) {
  auto store = open();
  const JobId a = store->addJob(meshJob("a"), "s").id;
  const JobId b = store->addJob(meshJob("b"), "s").id;
  std::vector<std::pair<JobId, JobId>> pairs;
  store->eachJob([&](const JobRecord& outer) {
    EXPECT_EQ(store->job(outer.id)->source, outer.source);
    store->eachJob([&](const JobRecord& inner) { pairs.emplace_back(outer.id, inner.id); });
  });
  EXPECT_EQ(pairs, (std::vector<std::pair<JobId, JobId>>{{a, a}, {a, b}, {b, a}, {b, b}}));

  store->reorder(a, 0, 100.0);
  const JobRecord c = store->addJob(meshJob("c"), "s");
  // Found by an index, not by reading every job (schema version 4). (Shown
  // for SQLite; PostgreSQL's planner reads a table this small whole.)
  if (GetParam() == StoreEngine::Sqlite) {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file().c_str(), &db), SQLITE_OK);
    sqlite3_stmt* plan = nullptr;
    ASSERT_EQ(
        sqlite3_prepare_v2(db, "EXPLAIN QUERY PLAN SELECT COALESCE(MAX(position), 0) FROM jobs", -1, &plan, nullptr),
        SQLITE_OK);
    std::string steps;
    while (sqlite3_step(plan) == SQLITE_ROW) steps += reinterpret_cast<const char*>(sqlite3_column_text(plan, 3));
    sqlite3_finalize(plan);
    sqlite3_close(db);
    EXPECT_NE(steps.find("jobs_position"), std::string::npos) << steps;
  }
  EXPECT_GT(c.position, 100.0);
  std::vector<JobId> order;
  for (const JobRecord& job : store->jobs()) order.push_back(job.id);
  EXPECT_EQ(order, (std::vector<JobId>{b, a, c.id}));
}

TEST_P(Stores, WhatWasWrittenIsThereAfterTheStoreIsOpenedAgain) {
  JobId id = 0;
  {
    auto store = open();
    id = store->addJob(meshJob("bunny.obj"), "submitted").id;
    store->transition(id, JobState::Planning, "planning");
    JobChange progress;
    progress.sheet = 2;
    progress.stroke = 40;
    progress.strokes = 108;
    store->update(id, progress);
    store->addEvent(id, "sheet", "sheet 2 of 3 started");
  }
  auto store = open();
  const auto job = store->job(id);
  ASSERT_TRUE(job);
  EXPECT_EQ(job->state, JobState::Planning);
  EXPECT_EQ(job->sheet, 2);
  EXPECT_EQ(job->stroke, 40);
  EXPECT_EQ(job->owner, "alice");
  ASSERT_EQ(store->events(id, 10).size(), 1u);
  EXPECT_EQ(store->events(id, 10)[0].text, "sheet 2 of 3 started");
  EXPECT_EQ(store->integrityCheck(), "ok");
  if (GetParam() == StoreEngine::Postgres) return;
  // WAL mode, synchronous FULL: what the issue asks of the store's durability.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file().c_str(), &db), SQLITE_OK);
  sqlite3_stmt* mode = nullptr;
  sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &mode, nullptr);
  ASSERT_EQ(sqlite3_step(mode), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(mode, 0)), "wal");
  sqlite3_finalize(mode);
  sqlite3_close(db);
}

// A store whose jobs and transitions disagree is found out, in words that name the job.
TEST_P(Stores, TheIntegrityCheckFindsAJobWhoseHistoryDisagreesWithIt) {
  auto store = open();
  const JobId a = store->addJob(meshJob("a"), "s").id;
  const JobId b = store->addJob(meshJob("b"), "s").id;
  store->transition(b, JobState::Planning, "planning");
  EXPECT_EQ(store->integrityCheck(), "ok");
  sql(fmt::format("UPDATE jobs SET state = 'running' WHERE id = {}", a));
  sql(
      fmt::format("INSERT INTO transitions (job, from_state, to_state, at, reason) VALUES ({}, NULL, 'queued', 0, "
                  "'again')",
                  b));
  EXPECT_EQ(store->integrityCheck(), fmt::format("job {} is running but its last transition ended in queued; job {} is "
                                                 "planning but its last transition ended in queued; job {} was "
                                                 "submitted 2 times",
                                                 a, b, b));
}

TEST_P(Stores, TheSchemaIsMigratedFromEachVersionUp) {
  for (int from = 0; from <= newestSchemaVersion(); ++from) {
    fresh();
    JobId id = 0;
    {
      auto old = open(from);
      EXPECT_EQ(old->schemaVersion(), from);
      if (from >= 1) id = old->addJob(meshJob("kept.obj"), "submitted before the migration").id;
    }
    auto store = open();
    EXPECT_EQ(store->schemaVersion(), newestSchemaVersion());
    EXPECT_EQ(store->integrityCheck(), "ok");
    if (id != 0) {
      ASSERT_TRUE(store->job(id)) << "from version " << from;
      EXPECT_EQ(store->job(id)->source, "kept.obj");
      EXPECT_EQ(store->transitions(id).size(), 1u);
    }
    store->addEvent(std::nullopt, "device", "laser1: idle");
    EXPECT_EQ(store->events(std::nullopt, 5).size(), 1u);
  }
}

TEST_P(Stores, AStoreOfANewerSchemaIsRefusedInOneLine) {
  { open(); }
  sql(GetParam() == StoreEngine::Sqlite ? "PRAGMA user_version = 99" : "UPDATE rotafab_schema SET version = 99");
  try {
    open();
    FAIL();
  } catch (const StoreError& error) {
    EXPECT_NE(std::string(error.what()).find("schema version 99, made by a newer rotafabd"), std::string::npos)
        << error.what();
    EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << error.what();
  }
}

TEST(JobStore, AFileThatIsNotADatabaseIsRefusedInOneLine) {
  TempDir dir;
  const auto garbage = dir.write("garbage.sqlite3", std::string(4096, 'x'));
  try {
    openSqliteStore(garbage);
    FAIL();
  } catch (const StoreError& error) {
    EXPECT_NE(std::string(error.what()).find("not a sound SQLite database"), std::string::npos) << error.what();
  }
}

// A server that is not there, or a database that is not: one line naming
// the store, and never its password.
TEST(JobStore, APostgresStoreThatCannotBeReachedIsOneLineWithoutItsPassword) {
  const std::string server = test::testServerUri();
  const std::string port = server.substr(server.rfind(':') + 1, server.rfind('/') - server.rfind(':') - 1);
  for (const std::string& uri : {std::string("postgresql://rotafab:s3cret@127.0.0.1:1/jobs"),
                                 "postgresql://rotafab:s3cret@127.0.0.1:" + port + "/no_such_database"}) {
    SCOPED_TRACE(uri);
    try {
      openPostgresStore(uri);
      FAIL();
    } catch (const StoreError& error) {
      const std::string what = error.what();
      EXPECT_TRUE(what.starts_with(uriWithoutPassword(uri) + ": cannot reach the job store: ")) << what;
      EXPECT_EQ(what.find("s3cret"), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  EXPECT_EQ(uriWithoutPassword("postgresql://ann:pw@db:5432/jobs"), "postgresql://ann:***@db:5432/jobs");
  EXPECT_EQ(uriWithoutPassword("postgresql://ann@db:5432/jobs"), "postgresql://ann@db:5432/jobs");
}

HostRecord host(const std::string& name) { return {name, "http://127.0.0.1:1/" + name, 0, 0, 0, false}; }

DeviceRecord device(const std::string& name, const std::string& machine = "grbl-diode-400") {
  DeviceRecord record;
  record.name = name;
  record.machine = machine;
  record.material = "posterboard";
  record.uri = "sim:grbl";
  record.state = "idle";
  return record;
}

const Release kReleased = [](const JobRecord& job, const HostRecord& by) {
  return std::pair{holdsDevice(job.state) ? JobState::Interrupted : JobState::Queued, "released from " + by.name};
};

// A host name is one daemon's at a time on a shared store: a second daemon
// under it waits for the first one's lease, then is refused; and a device
// name is one host's.
TEST(JobStore, OnASharedStoreAHostNameAndADeviceNameAreOneDaemonsAtATime) {
  test::TestDatabase database;
  auto first = openPostgresStore(database.uri());
  ASSERT_TRUE(first->shared());
  EXPECT_TRUE(first->join(host("a"), {device("laser1")}, 30, 0, kReleased).empty());
  auto second = openPostgresStore(database.uri());
  try {
    second->join(host("a"), {}, 30, 0.3, kReleased);
    FAIL();
  } catch (const StoreError& error) {
    EXPECT_NE(std::string(error.what()).find("another rotafabd runs as host a on this job store"), std::string::npos)
        << error.what();
  }
  try {
    second->join(host("b"), {device("laser1")}, 30, 0, kReleased);
    FAIL();
  } catch (const StoreError& error) {
    EXPECT_NE(std::string(error.what()).find("device laser1 is host a's"), std::string::npos) << error.what();
  }
  EXPECT_NO_THROW(second->join(host("b"), {device("laser2")}, 30, 0, kReleased));
  const auto devices = second->devices();
  ASSERT_EQ(devices.size(), 2u);
  EXPECT_EQ(devices[0].host, "a");
  EXPECT_EQ(devices[1].host, "b");
}

// Hosts claiming at once from one queue: each job claimed by exactly one,
// which then holds it (and only it moves it).
TEST(JobStore, JobsClaimedByTwoHostsAtOnceAreEachClaimedOnce) {
  test::TestDatabase database;
  {
    auto store = openPostgresStore(database.uri());
    for (int i = 0; i < 60; ++i) store->addJob(meshJob(fmt::format("j{}", i)), "s");
  }
  std::map<std::string, std::vector<JobId>> claimed;
  std::vector<std::thread> hosts;
  std::mutex mutex;
  for (const std::string name : {"a", "b", "c"}) {
    hosts.emplace_back([&, name] {
      auto store = openPostgresStore(database.uri());
      store->join(host(name), {device("laser-" + name)}, 30, 0, kReleased);
      for (;;) {
        const auto taken = store->claim({JobState::Queued, 2, "", "", ""}, [&](const JobRecord&) {
          return std::optional<Claim>(Claim{JobState::Planning, "planning on " + name, {}});
        });
        if (taken.empty()) return;
        std::lock_guard lock(mutex);
        for (const JobRecord& job : taken) {
          EXPECT_EQ(job.host, name);
          claimed[name].push_back(job.id);
        }
      }
    });
  }
  for (std::thread& thread : hosts) thread.join();
  std::set<JobId> once;
  size_t total = 0;
  for (const auto& [name, ids] : claimed) {
    total += ids.size();
    once.insert(ids.begin(), ids.end());
  }
  EXPECT_EQ(total, 60u);
  EXPECT_EQ(once.size(), 60u);
  auto store = openPostgresStore(database.uri());
  store->join(host("d"), {}, 30, 0, kReleased);
  const JobId someone = *once.begin();
  try {
    store->transition(someone, JobState::Ready, "planned by d");
    FAIL();
  } catch (const TransitionRefused& error) {
    EXPECT_NE(std::string(error.what()).find(" is planning on host "), std::string::npos) << error.what();
  }
  for (const JobRecord& job : store->jobs()) EXPECT_EQ(store->transitions(job.id).size(), 2u) << job.id;
  EXPECT_EQ(store->integrityCheck(), "ok");
}

// A host whose lease runs out: another host releases its jobs, once (its
// plan made again, its cut interrupted), its devices are gone with it, and
// it no longer moves or writes to them.
TEST(JobStore, ALapsedHostsJobsAreReleasedOnceByAnotherHost) {
  test::TestDatabase database;
  auto a = openPostgresStore(database.uri());
  auto b = openPostgresStore(database.uri());
  auto c = openPostgresStore(database.uri());
  a->join(host("a"), {device("laser-a")}, 3, 0, kReleased);
  b->join(host("b"), {device("laser-b")}, 30, 0, kReleased);
  c->join(host("c"), {}, 30, 0, kReleased);
  const JobId planned = a->addJob(meshJob("planned"), "s").id;
  const JobId cut = a->addJob(meshJob("cut"), "s").id;
  const auto claim = [&](JobStore& store, JobState from, JobState to) {
    return store.claim({from, 1, "", "", ""}, [&](const JobRecord&) {
      return std::optional<Claim>(Claim{to, "", {}});
    });
  };
  ASSERT_EQ(claim(*a, JobState::Queued, JobState::Planning).size(), 1u);
  a->transition(planned, JobState::Ready, "planned");
  ASSERT_EQ(claim(*a, JobState::Ready, JobState::Running).front().id, planned);
  ASSERT_EQ(claim(*a, JobState::Queued, JobState::Planning).front().id, cut);
  EXPECT_TRUE(b->releaseLapsedHosts(kReleased).empty());  // its lease still runs
  std::this_thread::sleep_for(std::chrono::milliseconds(3300));
  std::vector<JobRecord> byB, byC;
  std::thread other([&] { byC = c->releaseLapsedHosts(kReleased); });
  byB = b->releaseLapsedHosts(kReleased);
  other.join();
  ASSERT_EQ(byB.size() + byC.size(), 2u);
  EXPECT_EQ(b->job(planned)->state, JobState::Interrupted);
  EXPECT_EQ(b->job(planned)->message, "released from a");
  EXPECT_EQ(b->job(cut)->state, JobState::Queued);
  EXPECT_EQ(b->job(cut)->host, "");
  EXPECT_FALSE(a->heartbeat(1));
  // Its progress no longer lands on the job it lost; and once another host
  // plans that job, the lapsed host cannot move it (the table would allow
  // planning to ready; the holder does not).
  JobChange progress;
  progress.sheet = 7;
  a->update(planned, progress);
  EXPECT_EQ(b->job(planned)->sheet, 0);
  ASSERT_EQ(claim(*b, JobState::Queued, JobState::Planning).front().id, cut);
  try {
    a->transition(cut, JobState::Ready, "planned");
    FAIL();
  } catch (const TransitionRefused& error) {
    EXPECT_NE(std::string(error.what()).find("is planning on host b"), std::string::npos) << error.what();
  }
  for (const HostRecord& h : b->hosts()) EXPECT_EQ(h.gone, h.name == "a") << h.name;
  for (const DeviceRecord& d : b->devices()) EXPECT_EQ(d.state == "gone", d.host == "a") << d.name;
  // Joined again, it starts afresh.
  EXPECT_TRUE(a->join(host("a"), {device("laser-a")}, 1, 0, kReleased).empty());
  EXPECT_TRUE(a->heartbeat(1));
  EXPECT_EQ(b->integrityCheck(), "ok");
}

// An action for a job another host holds waits in the store for that host,
// which takes it once; one for a job nobody holds any more is taken by
// whichever host asks first (a cancel is never lost).
TEST(JobStore, AnActionForAJobAnotherHostHoldsIsTakenOnceByThatHost) {
  test::TestDatabase database;
  auto a = openPostgresStore(database.uri());
  auto b = openPostgresStore(database.uri());
  a->join(host("a"), {}, 30, 0, kReleased);
  b->join(host("b"), {}, 30, 0, kReleased);
  const JobId held = a->addJob(meshJob("held"), "s").id;
  const JobId queued = a->addJob(meshJob("queued"), "s").id;
  ASSERT_EQ(a->claim({JobState::Queued, 1, "", "", ""},
                     [](const JobRecord&) {
                       return std::optional<Claim>(Claim{JobState::Planning, "", {}});
                     })
                .front()
                .id,
            held);
  ActionRequest cancel{0, held, "cancel", "{}", "alice", 0};
  EXPECT_EQ(a->requestAction(cancel), std::nullopt);  // its own: it acts itself
  EXPECT_EQ(b->requestAction(cancel), std::optional<std::string>("a"));
  EXPECT_EQ(b->requestAction({0, queued, "cancel", "{}", "alice", 0}), std::nullopt);  // nobody holds it
  EXPECT_TRUE(b->takeRequests().empty());
  const auto taken = a->takeRequests();
  ASSERT_EQ(taken.size(), 1u);
  EXPECT_EQ(taken[0].job, held);
  EXPECT_EQ(taken[0].action, "cancel");
  EXPECT_EQ(taken[0].who, "alice");
  EXPECT_TRUE(a->takeRequests().empty());
  // Left for a host that then let the job go: taken once, by any host.
  ASSERT_TRUE(b->requestAction({0, held, "cancel", "{}", "bob", 0}));
  a->transition(held, JobState::Queued, "stopped");
  const auto stale = b->takeRequests();
  ASSERT_EQ(stale.size(), 1u);
  EXPECT_EQ(stale[0].who, "bob");
  EXPECT_TRUE(a->takeRequests().empty());
  EXPECT_EQ(b->integrityCheck(), "ok");
}

// The server ended the store's connection (a restart, an administrator):
// the store connects again at its next call, as it was opened.
TEST(JobStore, APostgresStoreWhoseConnectionWasEndedConnectsAgain) {
  test::TestDatabase database;
  auto store = openPostgresStore(database.uri());
  const JobId id = store->addJob(meshJob("a"), "s").id;
  const auto endItsConnections = [&] {
    test::serverSql("SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = '" + database.name() +
                    "' AND pid <> pg_backend_pid()");
  };
  endItsConnections();
  EXPECT_EQ(store->job(id)->source, "a");
  endItsConnections();
  EXPECT_EQ(store->addJob(meshJob("b"), "s").id, id + 1);  // a transaction's BEGIN connects again too
  EXPECT_EQ(store->integrityCheck(), "ok");
}

// Several connections adding jobs at once (as several hosts will): each job
// once, each at a place of its own at the end of the queue.
TEST(JobStore, JobsAddedThroughSeveralConnectionsAtOnceEachGetAPlaceOfTheirOwn) {
  test::TestDatabase database;
  { openPostgresStore(database.uri()); }
  std::vector<std::thread> hosts;
  for (int host = 0; host < 4; ++host) {
    hosts.emplace_back([&, host] {
      auto store = openPostgresStore(database.uri());
      for (int i = 0; i < 25; ++i) store->addJob(meshJob(fmt::format("h{}-{}", host, i)), "s");
    });
  }
  for (std::thread& host : hosts) host.join();
  auto store = openPostgresStore(database.uri());
  const auto all = store->jobs();
  ASSERT_EQ(all.size(), 100u);
  std::set<double> positions;
  std::set<std::string> sources;
  for (const JobRecord& job : all) {
    positions.insert(job.position);
    sources.insert(job.source);
  }
  EXPECT_EQ(positions.size(), 100u);
  EXPECT_EQ(sources.size(), 100u);
  EXPECT_EQ(store->integrityCheck(), "ok");
}

}  // namespace
}  // namespace rotafab::service
