#pragma once
// A PostgreSQL database of a test's own, on the server ctest starts for the
// daemon's tests (scripts/test-postgres.sh, a fixture in CMakeLists.txt),
// dropped when the test ends.

#include <gtest/gtest.h>
#include <libpq-fe.h>

#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace rotafab::test {

// The tests' server, as its start wrote it: postgresql://rotafab@127.0.0.1:PORT/postgres.
inline std::string testServerUri() {
  std::ifstream file(std::string(ROTAFAB_TEST_POSTGRES_DIR) + "/uri");
  std::string uri;
  if (!(file >> uri)) {
    throw std::runtime_error(std::string("no PostgreSQL server for the tests (") + ROTAFAB_TEST_POSTGRES_DIR +
                             "/uri): run the tests with ctest, whose fixture PostgreSQL.Start starts it");
  }
  return uri;
}

// One statement on the tests' server (its `postgres` database, or `uri`); fails the test if refused.
inline void serverSql(const std::string& statement, const std::string& uri = testServerUri()) {
  PGconn* connection = PQconnectdb(uri.c_str());
  ASSERT_EQ(PQstatus(connection), CONNECTION_OK) << PQerrorMessage(connection);
  PGresult* result = PQexec(connection, statement.c_str());
  const ExecStatusType status = PQresultStatus(result);
  EXPECT_TRUE(status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK)
      << statement << ": " << PQresultErrorMessage(result);
  PQclear(result);
  PQfinish(connection);
}

class TestDatabase {
 public:
  TestDatabase() {
    std::random_device random;
    name_ = "rotafab_test_" + std::to_string(random()) + std::to_string(random());
    const std::string server = testServerUri();
    serverSql("CREATE DATABASE " + name_, server);
    uri_ = server.substr(0, server.rfind('/') + 1) + name_;
  }
  ~TestDatabase() { serverSql("DROP DATABASE IF EXISTS " + name_ + " WITH (FORCE)"); }
  TestDatabase(const TestDatabase&) = delete;
  TestDatabase& operator=(const TestDatabase&) = delete;

  [[nodiscard]] const std::string& uri() const { return uri_; }
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::string name_, uri_;
};

}  // namespace rotafab::test
