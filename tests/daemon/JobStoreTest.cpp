// The job store (daemon/service/JobStore.h) on a real SQLite file: the
// table of transitions enforced and every move recorded, the queue's order,
// what survives closing the file, and the schema migrated from its first
// version up.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include "daemon/service/JobStore.h"
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

void sql(const std::filesystem::path& file, const std::string& statement) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, statement.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

TEST(JobStore, TheTableOfTransitionsIsEnforcedAndEveryMoveRecorded) {
  TempDir dir;
  auto store = openSqliteStore(dir.path() / "jobs.sqlite3");
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

TEST(JobStore, AJobsFirstStepsAreRecordedWithItsSubmissionOrNotAtAll) {
  TempDir dir;
  auto store = openSqliteStore(dir.path() / "jobs.sqlite3");
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
      // Nothing goes back to queued but a plan the daemon's stop broke off.
      if (to == JobState::Queued) {
        EXPECT_EQ(allowedTransition(from, to), from == JobState::Planning);
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

TEST(JobStore, TheQueueIsInPriorityThenSubmissionOrderAndCanBeReordered) {
  TempDir dir;
  auto store = openSqliteStore(dir.path() / "jobs.sqlite3");
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
TEST(JobStore, AVisitMayQueryTheStoreAgainAndANewJobGoesLast) {
  TempDir dir;
  auto store = openSqliteStore(dir.path() / "jobs.sqlite3");
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
  // Found by an index, not by reading every job (schema version 4).
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open((dir.path() / "jobs.sqlite3").c_str(), &db), SQLITE_OK);
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

TEST(JobStore, WhatWasWrittenIsThereAfterTheFileIsOpenedAgain) {
  TempDir dir;
  const auto file = dir.path() / "jobs.sqlite3";
  JobId id = 0;
  {
    auto store = openSqliteStore(file);
    id = store->addJob(meshJob("bunny.obj"), "submitted").id;
    store->transition(id, JobState::Planning, "planning");
    JobChange progress;
    progress.sheet = 2;
    progress.stroke = 40;
    progress.strokes = 108;
    store->update(id, progress);
    store->addEvent(id, "sheet", "sheet 2 of 3 started");
  }
  auto store = openSqliteStore(file);
  const auto job = store->job(id);
  ASSERT_TRUE(job);
  EXPECT_EQ(job->state, JobState::Planning);
  EXPECT_EQ(job->sheet, 2);
  EXPECT_EQ(job->stroke, 40);
  EXPECT_EQ(job->owner, "alice");
  ASSERT_EQ(store->events(id, 10).size(), 1u);
  EXPECT_EQ(store->events(id, 10)[0].text, "sheet 2 of 3 started");
  EXPECT_EQ(store->integrityCheck(), "ok");
  // WAL mode, synchronous FULL: what the issue asks of the store's durability.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* mode = nullptr;
  sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &mode, nullptr);
  ASSERT_EQ(sqlite3_step(mode), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(mode, 0)), "wal");
  sqlite3_finalize(mode);
  sqlite3_close(db);
}

TEST(JobStore, TheSchemaIsMigratedFromEachVersionUp) {
  for (int from = 0; from <= newestSchemaVersion(); ++from) {
    TempDir dir;
    const auto file = dir.path() / "jobs.sqlite3";
    JobId id = 0;
    {
      auto old = openSqliteStore(file, from);
      EXPECT_EQ(old->schemaVersion(), from);
      if (from >= 1) id = old->addJob(meshJob("kept.obj"), "submitted before the migration").id;
    }
    auto store = openSqliteStore(file);
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

TEST(JobStore, AStoreOfANewerSchemaOrNotADatabaseIsRefusedInOneLine) {
  TempDir dir;
  const auto newer = dir.path() / "newer.sqlite3";
  { openSqliteStore(newer); }
  sql(newer, "PRAGMA user_version = 99");
  try {
    openSqliteStore(newer);
    FAIL();
  } catch (const StoreError& error) {
    EXPECT_NE(std::string(error.what()).find("schema version 99, made by a newer rotafabd"), std::string::npos)
        << error.what();
  }
  const auto garbage = dir.write("garbage.sqlite3", std::string(4096, 'x'));
  try {
    openSqliteStore(garbage);
    FAIL();
  } catch (const StoreError& error) {
    EXPECT_NE(std::string(error.what()).find("not a sound SQLite database"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace rotafab::service
