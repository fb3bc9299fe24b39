// The daemon's benchmark (docs/PERFORMANCE.md, "The daemon"): a real
// rotafabd on its Unix socket, against the disk it keeps its state on.
//
//   1. the rate of bare SQLite transactions (WAL, synchronous=FULL) on that
//      disk: the limit a durable submission cannot beat;
//   2. submissions of a planned `make` folder per second, from 1 and from 8
//      clients at once, each a new connection, then each client's on one
//      connection kept open;
//   3. status queries per second (GET /api/jobs/ID), 4 clients;
//   4. with 10,000 jobs in the store: the time from the daemon's start to its
//      first answer, and its memory (VmRSS) then and after a list of all;
//   5. on a shared PostgreSQL store (a server of its own, started with
//      scripts/test-postgres.sh, or --postgres URI), with 1, 2 and 3 hosts:
//      submissions per second through the hosts (8 clients spread over
//      them, each on one connection kept open), and claims per second of
//      the store (each host's connection claiming queued jobs for planning
//      at once, FOR UPDATE SKIP LOCKED), beside SQLite's claims.
//
//   build/rotafab_daemon_bench [--dir DIR] [--jobs 10000] [--postgres URI] [--only-shared]

#include <fcntl.h>
#include <fmt/format.h>
#include <libpq-fe.h>
#include <signal.h>
#include <spawn.h>
#include <sqlite3.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "daemon/service/JobStore.h"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double bareSqliteRate(const fs::path& dir, int transactions) {
  const fs::path file = dir / "bare.sqlite3";
  sqlite3* db = nullptr;
  sqlite3_open(file.c_str(), &db);
  sqlite3_exec(db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; CREATE TABLE t (a INTEGER, b TEXT)", nullptr,
               nullptr, nullptr);
  sqlite3_stmt* insert = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO t VALUES (?, ?)", -1, &insert, nullptr);
  const auto start = Clock::now();
  for (int i = 0; i < transactions; ++i) {
    sqlite3_exec(db, "BEGIN IMMEDIATE", nullptr, nullptr, nullptr);
    sqlite3_bind_int(insert, 1, i);
    sqlite3_bind_text(insert, 2, "a job row of about this many bytes: owner, source, options", -1, SQLITE_STATIC);
    sqlite3_step(insert);
    sqlite3_reset(insert);
    sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  }
  const double rate = transactions / since(start);
  sqlite3_finalize(insert);
  sqlite3_close(db);
  return rate;
}

int connectTo(const fs::path& socket) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", socket.c_str());
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// One request on a new connection; the status code of the reply.
int request(const fs::path& socket, const std::string& bytes) {
  const int fd = connectTo(socket);
  if (fd < 0) return 0;
  ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  std::string reply;
  char chunk[8192];
  for (ssize_t n; (n = ::recv(fd, chunk, sizeof chunk, 0)) > 0;) reply.append(chunk, static_cast<size_t>(n));
  ::close(fd);
  return reply.size() > 12 ? std::stoi(reply.substr(9, 3)) : 0;
}

// Requests one after another on one connection kept open (HTTP/1.1
// keep-alive), as a client that submits a batch would send them.
class KeptConnection {
 public:
  explicit KeptConnection(const fs::path& socket) : socket_(socket) {}
  ~KeptConnection() { closeIt(); }
  KeptConnection(const KeptConnection&) = delete;
  KeptConnection& operator=(const KeptConnection&) = delete;

  // The status code of the reply; the connection opened again when the server closed it.
  int exchange(const std::string& bytes) {
    if (fd_ < 0 && (fd_ = connectTo(socket_)) < 0) return 0;
    if (::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(bytes.size())) {
      closeIt();
      return 0;
    }
    // The head, then as many bytes of body as it says.
    size_t headEnd;
    while ((headEnd = buffer_.find("\r\n\r\n")) == std::string::npos) {
      if (!receive()) return 0;
    }
    const std::string head = buffer_.substr(0, headEnd);
    size_t length = 0;
    if (const auto at = head.find("Content-Length: "); at != std::string::npos) {
      length = std::stoul(head.substr(at + 16));
    }
    while (buffer_.size() < headEnd + 4 + length) {
      if (!receive()) return 0;
    }
    buffer_.erase(0, headEnd + 4 + length);
    if (head.find("Connection: close") != std::string::npos) closeIt();
    return head.size() > 12 ? std::stoi(head.substr(9, 3)) : 0;
  }

 private:
  bool receive() {
    char chunk[8192];
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n <= 0) {
      closeIt();
      return false;
    }
    buffer_.append(chunk, static_cast<size_t>(n));
    return true;
  }
  void closeIt() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    buffer_.clear();
  }
  fs::path socket_;
  int fd_ = -1;
  std::string buffer_;
};

struct Daemon {
  pid_t pid = 0;
  fs::path root;
  fs::path socket() const { return root / "run/rotafab/rotafabd.sock"; }
  void start() {
    const std::string state = "XDG_STATE_HOME=" + (root / "state").string(),
                      run = "XDG_RUNTIME_DIR=" + (root / "run").string(), config = (root / "rotafabd.yaml").string();
    std::vector<char*> env;
    for (char** e = environ; *e; ++e) env.push_back(*e);
    env.push_back(const_cast<char*>(state.c_str()));
    env.push_back(const_cast<char*>(run.c_str()));
    env.push_back(nullptr);
    std::string program = ROTAFAB_DAEMON, flag = "--config";
    char* argv[] = {program.data(), flag.data(), const_cast<char*>(config.c_str()), nullptr};
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    const std::string log = (root / "daemon.log").string();
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn(&pid, program.c_str(), &actions, nullptr, argv, env.data());
    posix_spawn_file_actions_destroy(&actions);
  }
  // Seconds until it answers GET /api.
  double waitServing() const {
    const auto start = Clock::now();
    while (request(socket(), "GET /api HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n") != 200) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      if (since(start) > 60) return -1;
    }
    return since(start);
  }
  long rssKiB() const {
    std::ifstream status(fmt::format("/proc/{}/status", pid));
    for (std::string line; std::getline(status, line);) {
      if (line.starts_with("VmRSS:")) return std::stol(line.substr(6));
    }
    return -1;
  }
  void stop() {
    ::kill(pid, SIGTERM);
    ::waitpid(pid, nullptr, 0);
  }
};

// Submissions of `folder` by path from `clients` threads for about
// `seconds`, each on a new connection or each client's on one kept open; per second.
double submissionRate(const fs::path& socket, const fs::path& folder, int clients, double seconds, bool keptAlive) {
  const std::string body = fmt::format(R"({{"path": "{}"}})", folder.string());
  const std::string bytes = fmt::format(
      "POST /api/jobs HTTP/1.1\r\nHost: x\r\n{}Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{}",
      keptAlive ? "" : "Connection: close\r\n", body.size(), body);
  std::atomic<int> done{0}, failed{0};
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&] {
      KeptConnection connection(socket);
      while (since(start) < seconds) {
        (((keptAlive ? connection.exchange(bytes) : request(socket, bytes)) == 201) ? done : failed)++;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  if (failed > 0) fmt::print(stderr, "  ({} submissions refused)\n", failed.load());
  return done / since(start);
}

double statusRate(const fs::path& socket, int clients, double seconds) {
  const std::string bytes = "GET /api/jobs/1 HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n";
  std::atomic<int> done{0};
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&] {
      while (since(start) < seconds) done += request(socket, bytes) == 200 ? 1 : 0;
    });
  }
  for (auto& thread : threads) thread.join();
  return done / since(start);
}

// One statement on the server at `uri`; false (and what it said) when refused.
bool serverSql(const std::string& uri, const std::string& sql) {
  PGconn* connection = PQconnectdb(uri.c_str());
  PQsetNoticeProcessor(
      connection, [](void*, const char*) {}, nullptr);  // ("does not exist, skipping")
  PGresult* result = PQexec(connection, sql.c_str());
  const bool ok = PQresultStatus(result) == PGRES_COMMAND_OK;
  if (!ok) fmt::print(stderr, "{}: {}", sql, PQerrorMessage(connection));
  PQclear(result);
  PQfinish(connection);
  return ok;
}

// `jobs` queued jobs claimed for planning by `hosts` connections at once,
// one job per claim, as each daemon's queue claims them; claims per second.
double claimRate(const std::function<std::unique_ptr<rotafab::service::JobStore>()>& open, int hosts, int jobs) {
  using namespace rotafab::service;
  {
    auto store = open();
    std::vector<NewJob> batch;
    for (int i = 0; i < jobs; ++i) {
      NewJob job;
      job.source = fmt::format("mesh-{}.obj", i);
      job.owner = "bench";
      job.options = "[]";
      job.spool = fmt::format("job-{}", i);
      batch.push_back(job);
    }
    store->addJobs(batch, std::vector<std::string>(batch.size(), "submitted"));
  }
  std::vector<std::unique_ptr<JobStore>> stores;
  for (int h = 0; h < hosts; ++h) {
    stores.push_back(open());
    stores.back()->join({fmt::format("claimer-{}", h), "", 0, 0, 0, false}, {}, 60, 0,
                        [](const JobRecord&, const HostRecord&) {
                          return std::pair{JobState::Queued, std::string()};
                        });
  }
  std::atomic<int> claimed{0};
  const auto start = Clock::now();
  std::vector<std::thread> threads;
  for (int h = 0; h < hosts; ++h) {
    threads.emplace_back([&, h] {
      for (;;) {
        const auto taken = stores[h]->claim({JobState::Queued, 1, "", "", ""}, [](const JobRecord&) {
          return std::optional<Claim>(Claim{JobState::Planning, "planning", {}});
        });
        if (taken.empty()) return;
        claimed += static_cast<int>(taken.size());
      }
    });
  }
  for (auto& thread : threads) thread.join();
  const double rate = claimed / since(start);
  if (claimed != jobs) fmt::print(stderr, "  ({} of {} jobs claimed)\n", claimed.load(), jobs);
  return rate;
}

// Part 5: several hosts on one PostgreSQL store.
void sharedStore(const fs::path& dir, const fs::path& planned, std::string server) {
  bool ours = false;
  if (server.empty()) {
    const fs::path cluster = dir / "postgres";
    const std::string start =
        fmt::format("bash {}/scripts/test-postgres.sh start {} >/dev/null", ROTAFAB_SOURCE_DIR, cluster.string());
    if (std::system(start.c_str()) != 0) {
      fmt::print(stderr, "no PostgreSQL server for the shared store's part (scripts/setup.sh installs one)\n");
      return;
    }
    std::ifstream(cluster / "uri") >> server;
    ours = true;
  }
  const auto database = [&](const std::string& name) {
    serverSql(server, "DROP DATABASE IF EXISTS " + name);
    serverSql(server, "CREATE DATABASE " + name);
    return server.substr(0, server.rfind('/') + 1) + name;
  };
  fmt::print("shared PostgreSQL store on {}:\n", server);
  for (int hosts : {1, 2, 3}) {
    const std::string uri = database(fmt::format("rotafab_bench_{}", hosts));
    const fs::path spool = dir / fmt::format("shared-{}-spool", hosts);
    std::vector<Daemon> daemons;
    for (int h = 0; h < hosts; ++h) {
      Daemon daemon{0, dir / fmt::format("shared-{}-host-{}", hosts, h)};
      fs::create_directories(daemon.root);
      std::ofstream(daemon.root / "rotafabd.yaml") << fmt::format(
          "store: {}\nhost: h{}\nspool: {}\ndevices: [{{name: laser{}, machine: grbl-diode-400, "
          "uri: \"sim:grbl?speed=100\"}}]\n",
          uri, h, spool.string(), h);
      daemon.start();
      daemons.push_back(daemon);
    }
    for (const Daemon& daemon : daemons) daemon.waitServing();
    // 8 clients, client c through host c % hosts.
    std::atomic<int> done{0}, failed{0};
    const std::string body = fmt::format(R"({{"path": "{}"}})", planned.string());
    const std::string bytes = fmt::format(
        "POST /api/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{}",
        body.size(), body);
    const auto start = Clock::now();
    std::vector<std::thread> threads;
    for (int c = 0; c < 8; ++c) {
      threads.emplace_back([&, c] {
        KeptConnection connection(daemons[static_cast<size_t>(c % hosts)].socket());
        while (since(start) < 5) (connection.exchange(bytes) == 201 ? done : failed)++;
      });
    }
    for (auto& thread : threads) thread.join();
    const double submissions = done / since(start);
    for (Daemon& daemon : daemons) daemon.stop();
    if (failed > 0) fmt::print(stderr, "  ({} submissions refused)\n", failed.load());
    const std::string claimsUri = database(fmt::format("rotafab_claims_{}", hosts));
    const double claims = claimRate([&] { return rotafab::service::openPostgresStore(claimsUri); }, hosts, 2000);
    fmt::print("  {} host{}: submissions of a planned folder, 8 clients: {:.0f}/s; claims: {:.0f}/s\n", hosts,
               hosts == 1 ? "" : "s", submissions, claims);
  }
  const fs::path file = dir / "claims.sqlite3";
  fmt::print("  SQLite (one daemon): claims: {:.0f}/s\n",
             claimRate([&] { return rotafab::service::openSqliteStore(file); }, 1, 2000));
  if (ours) {
    const std::string stop =
        fmt::format("bash {}/scripts/test-postgres.sh stop {}", ROTAFAB_SOURCE_DIR, (dir / "postgres").string());
    std::system(stop.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  fs::path dir = fs::temp_directory_path() / fmt::format("rotafab-daemon-bench-{}", ::getpid());
  int manyJobs = 10000;
  std::string postgres;
  bool onlyShared = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--dir") dir = fs::path(argv[i + 1]) / fmt::format("rotafab-daemon-bench-{}", ::getpid());
    if (flag == "--jobs") manyJobs = std::stoi(argv[i + 1]);
    if (flag == "--postgres") postgres = argv[i + 1];
  }
  for (int i = 1; i < argc; ++i) onlyShared = onlyShared || std::string(argv[i]) == "--only-shared";
  fs::create_directories(dir);
  // A planned folder: the cube on the default device's bed.
  const fs::path planned = dir / "cube";
  const std::string make = fmt::format(
      "{} make {}/examples/cube.obj --structure band --machine grbl-diode-400 --out {} "
      ">/dev/null 2>&1",
      ROTAFAB_CLI, ROTAFAB_SOURCE_DIR, planned.string());
  if (std::system(make.c_str()) != 0) {
    fmt::print(stderr, "cannot make the cube's folder\n");
    return 1;
  }
  fmt::print("state on {} (the disk of {})\n", dir.string(), fs::temp_directory_path().string());
  if (onlyShared) {
    sharedStore(dir, planned, postgres);
    fs::remove_all(dir);
    return 0;
  }
  const double bare = bareSqliteRate(dir, 3000);
  fmt::print("bare SQLite transactions (WAL, synchronous=FULL): {:.0f}/s\n", bare);

  Daemon daemon{0, dir / "queue"};
  fs::create_directories(daemon.root);
  std::ofstream(daemon.root / "rotafabd.yaml")
      << "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=100\"}]\n";
  daemon.start();
  daemon.waitServing();
  for (const bool keptAlive : {false, true}) {
    for (int clients : {1, 8}) {
      const double rate = submissionRate(daemon.socket(), planned, clients, 5, keptAlive);
      fmt::print("submissions of a planned folder, {} client{}{}: {:.0f}/s ({:.0f}% of bare SQLite)\n", clients,
                 clients == 1 ? "" : "s", keptAlive ? ", each on one connection kept open" : "", rate,
                 100 * rate / bare);
    }
  }
  fmt::print("status queries (GET /api/jobs/1), 4 clients: {:.0f}/s\n", statusRate(daemon.socket(), 4, 3));
  daemon.stop();

  // 10,000 jobs, most of them done, as a year of a busy workshop leaves them.
  Daemon full{0, dir / "full"};
  fs::create_directories(full.root / "state/rotafab");
  std::ofstream(full.root / "rotafabd.yaml")
      << "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=100\"}]\n";
  {
    auto store = rotafab::service::openSqliteStore(full.root / "state/rotafab/jobs.sqlite3");
    for (int i = 0; i < manyJobs; ++i) {
      rotafab::service::NewJob job;
      job.kind = rotafab::service::JobKind::Planned;
      job.source = fmt::format("/home/workshop/job-{}", i);
      job.owner = "alice";
      job.device = "laser1";
      job.options = "[]";
      job.spool = fmt::format("job-{:016x}", i);
      const auto id = store->addJob(job, "submitted by alice").id;
      if (i + 20 < manyJobs) {
        store->transition(id, rotafab::service::JobState::Cancelled, "cancelled by alice");
      }
    }
  }
  const auto started = Clock::now();
  full.start();
  const double serving = full.waitServing();
  fmt::print("with {} jobs in the store: serving {:.3f} s after the start (first answer {:.3f} s), VmRSS {:.1f} MiB\n",
             manyJobs, since(started), serving, full.rssKiB() / 1024.0);
  request(full.socket(), "GET /api/jobs HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
  fmt::print("  after listing all {} jobs: VmRSS {:.1f} MiB\n", manyJobs, full.rssKiB() / 1024.0);
  full.stop();
  sharedStore(dir, planned, postgres);
  fs::remove_all(dir);
  return 0;
}
