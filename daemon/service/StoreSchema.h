#pragma once
// The job store's schema, written once for both engines (SQLite and
// PostgreSQL): each migration is SQL that both accept, but for a few words
// that differ (an automatically numbered key, a 64-bit integer, a double),
// written as {key}, {integer} and {real} and put in each engine's words here.
// A store records the version it is at and is migrated one step at a time.

#include <string>
#include <vector>

namespace rotafab::service {

enum class StoreEngine { Sqlite, Postgres };

// The SQL that takes a store from schema version `from` to `from + 1`
// (statements separated by semicolons), in the engine's words.
std::string migrationSql(int from, StoreEngine engine);

// The newest schema version this program knows.
int newestSchemaVersion();

// The columns a job is read by, in this order, in a store at schema
// `version` (a store opened at an older one, as the migrations' tests do,
// reads the columns it has): id, state, kind, source, owner, device,
// priority, position, options, spool, submitted, updated, sheets, summary,
// sheet, stroke, strokes, message; from version 5 host and any_device.
std::string jobColumns(int version);
constexpr int kFirstVersionWithHosts = 5;

// Queries that find a store whose jobs and transitions disagree, each
// returning one row per fault with its description in the first column, in
// words both engines accept: a job in a state no program knows, a job whose
// last transition did not end in its state, a job submitted other than once.
const std::vector<std::string>& consistencyQueries();

}  // namespace rotafab::service
