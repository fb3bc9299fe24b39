// rotafabd probed as an attacker on the same machine would (docs/SECURITY.md):
// every route in every spelling of its path over TCP, with no token, a wrong
// one and the right one; another site's page asking for a cut; idle and
// slow connections that would lock the owner out; bodies nobody asked for;
// the state and socket as another account sees them.

#include <dirent.h>
#include <gtest/gtest.h>
#include <pwd.h>
#include <sys/stat.h>

#include <atomic>
#include <fstream>
#include <thread>

#include "daemon/DaemonSupport.h"
#include "daemon/service/DaemonConfig.h"

namespace rotafab::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr const char* kToken = "right-token-7f3a";

// A daemon under `root` that listens on its usual socket and on loopback TCP, with one token.
std::string tcpConfig(const fs::path& root, const std::string& more = "") {
  return fmt::format("listen: [\"unix:{}\", tcp://127.0.0.1:0]\ntokens: [{{name: alice, hash: \"{}\"}}]\n{}",
                     (root / "run/rotafab/rotafabd.sock").string(), service::hashToken(kToken, "5a17"), more);
}

// A sample target of every route (docs/API.md), its method, and the body it is sent.
struct Sample {
  std::string method, path, body;
};
std::vector<Sample> everyRoute() {
  std::vector<Sample> samples{{"GET", "/", ""},
                              {"GET", "/app/app.js", ""},
                              {"GET", "/lib/three/build/three.min.js", ""},
                              {"GET", "/login", ""},
                              {"GET", "/favicon.ico", ""},
                              {"GET", "/api", ""},
                              {"POST", "/api/sessions", "{}"},
                              {"GET", "/api/devices", ""},
                              {"GET", "/api/jobs", ""},
                              {"POST", "/api/jobs", "{}"},
                              {"GET", "/api/jobs/1", ""},
                              {"GET", "/api/jobs/1/manifest", ""},
                              {"GET", "/api/jobs/1/files/manifest.json", ""},
                              {"GET", "/api/jobs/1/sheets/1", ""}};
  // (Job 999 does not exist: its actions reach the queue, which says so, and start nothing.)
  for (const char* action : {"cancel", "pause", "resume", "start", "next", "move"}) {
    samples.push_back({"POST", fmt::format("/api/jobs/999/{}", action), "{}"});
  }
  return samples;
}

bool isPagesOwn(const std::string& path) {
  return !path.starts_with("/api");  // the page's files and the login link's landing
}

TEST(Security, EveryRouteInEverySpellingOverTcpAsksForATokenBeforeAnythingElse) {
  TempDir root;
  Daemon daemon(root.path(), tcpConfig(root.path()));
  daemon.start();
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  const int port = pagePort(daemon);
  ASSERT_GT(port, 0);
  const std::string json = "Content-Type: application/json\r\n";
  const std::string right = fmt::format("Authorization: Bearer {}\r\n", kToken);
  size_t asked = 0;
  for (const Sample& sample : everyRoute()) {
    const std::string headers = sample.body.empty() ? "" : json;
    // What the right token is answered on the path as written.
    const HttpReply canonical = overTcp(port, sample.method, sample.path, headers + right, sample.body);
    EXPECT_NE(canonical.status, 401) << sample.path;
    EXPECT_NE(canonical.status, 0) << sample.path;
    const std::string rest = sample.path.substr(1);
    std::vector<std::string> spellings{sample.path, "/" + sample.path, "/./" + rest, "/x/../" + rest,
                                       sample.path + "/"};
    if (!rest.empty()) spellings.push_back(fmt::format("/%{:02X}{}", static_cast<int>(rest[0]), rest.substr(1)));
    for (const std::string& spelling : spellings) {
      for (const std::string& token : {std::string(), std::string("Authorization: Bearer guess\r\n"), right}) {
        const HttpReply reply = overTcp(port, sample.method, spelling, headers + token, sample.body);
        ++asked;
        const std::string what = fmt::format("{} {} {}", sample.method, spelling, token.empty() ? "(none)" : token);
        if (token == right || isPagesOwn(sample.path)) {
          EXPECT_EQ(reply.status, canonical.status) << what << reply.body;
        } else {
          EXPECT_EQ(reply.status, 401) << what << reply.body;
          EXPECT_NE(reply.body.find("token"), std::string::npos) << what << reply.body;
        }
      }
    }
    // Another path, spelled like this one: never this one, and never anything to a stranger.
    std::string upper = sample.path;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (const std::string& other : {upper, "/%2F" + rest, sample.path + "%00", "/.." + sample.path}) {
      if (other == sample.path) continue;
      const HttpReply stranger = overTcp(port, sample.method, other, headers, sample.body);
      EXPECT_TRUE(stranger.status == 400 || stranger.status == 401) << other << ": " << stranger.status;
    }
  }
  EXPECT_GT(asked, 350u);
  // A body that breaks its own framing is answered, not dropped; a coding
  // the daemon does not read is refused before the body.
  for (const auto& [framing, status] :
       std::vector<std::pair<std::string, int>>{{"Transfer-Encoding: chunked\r\n\r\nzz\r\n{}\r\n0\r\n\r\n", 400},
                                                {"Transfer-Encoding: identity\r\n\r\n{}", 501}}) {
    const int fd = connectTcp(port);
    const RawReply reply = parseReply(rotafab::test::exchange(
        fd, fmt::format("POST /api/jobs/{}/pause HTTP/1.1\r\nHost: 127.0.0.1\r\n{}{}{}", id, right, json, framing)));
    ::close(fd);
    EXPECT_EQ(reply.status, status) << framing << ": " << reply.text;
  }
  EXPECT_EQ(state(daemon.job(id)), "ready");
}

TEST(Security, AnotherSitesPageCannotStartACutNorReadTheQueue) {
  TempDir root;
  const fs::path witness = root.path() / "laser";
  Daemon daemon(root.path(), tcpConfig(root.path(), witnessedLaser(50, witness)));
  daemon.start();
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  const int port = pagePort(daemon);
  const std::string start = fmt::format("//api/jobs/{}/start", id);
  const std::string right = fmt::format("Authorization: Bearer {}\r\n", kToken);
  // What a page of another site can send without a preflight: a form, or fetch with a "simple" type.
  const std::string evil = "Origin: http://evil.example\r\n";
  EXPECT_EQ(overTcp(port, "POST", start, evil + "Content-Type: text/plain\r\n", "{}").status, 401);
  EXPECT_EQ(overTcp(port, "POST", start, evil + right + "Content-Type: text/plain\r\n", "{}").status, 403);
  EXPECT_EQ(overTcp(port, "POST", start, right + "Content-Type: application/x-www-form-urlencoded\r\n", "a=b").status,
            415);
  EXPECT_EQ(overTcp(port, "POST", start, evil + right + "Content-Type: application/json\r\n", "{}").status, 403);
  EXPECT_EQ(
      overTcp(port, "POST", start, right + "Sec-Fetch-Site: cross-site\r\nContent-Type: application/json\r\n", "{}")
          .status,
      403);
  // A name that was made to point at this machine (DNS rebinding): refused by its Host, even to read.
  const int fd = connectTcp(port);
  ASSERT_GE(fd, 0);
  const RawReply rebound = parseReply(rotafab::test::exchange(
      fd, fmt::format("GET /api/jobs HTTP/1.1\r\nHost: evil.example:{}\r\nConnection: close\r\n{}\r\n", port, right)));
  ::close(fd);
  EXPECT_EQ(rebound.status, 421);
  // A token only in the Authorization header: never in the address.
  EXPECT_EQ(overTcp(port, "GET", fmt::format("/api/jobs?token={}", kToken)).status, 401);
  EXPECT_EQ(overTcp(port, "GET", fmt::format("/api/events?session={}", kToken)).status, 401);
  // None of it lit the laser or moved the job.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(state(daemon.job(id)), "ready");
  EXPECT_EQ(readFile(witness).find("on\n"), std::string::npos);
  // The page's own request does.
  EXPECT_EQ(overTcp(port, "POST", start,
                    fmt::format("Origin: http://127.0.0.1:{}\r\nSec-Fetch-Site: same-origin\r\n", port) + right +
                        "Content-Type: application/json\r\n",
                    "{}")
                .status,
            200);
  EXPECT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "running"; })), "running");
  daemon.client(fmt::format("cancel {}", id));
}

// Holds `count` idle TCP connections to `port` open (each having sent
// `opening`, such as part of a request's header), opening another whenever
// the daemon closes one, until stopped.
class Flood {
 public:
  Flood(int port, size_t count, std::string opening = "") {
    thread_ = std::thread([this, port, count, opening] {
      std::vector<int> open;
      while (!stop_) {
        while (open.size() < count && !stop_) {
          const int fd = connectTcp(port);
          if (fd < 0) break;
          timeval quick{0, 1000};
          ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &quick, sizeof quick);
          if (!opening.empty()) ::send(fd, opening.data(), opening.size(), MSG_NOSIGNAL);
          open.push_back(fd);
          ++opened_;
        }
        // Those the daemon closed (or refused with a 503) are opened again.
        std::erase_if(open, [&](int fd) {
          char byte;
          const ssize_t got = ::recv(fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT);
          if (got == 0 || (got > 0)) {
            ::close(fd);
            ++closed_;
            return true;
          }
          return false;
        });
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      for (int fd : open) ::close(fd);
    });
  }
  ~Flood() {
    stop_ = true;
    thread_.join();
  }
  [[nodiscard]] size_t opened() const { return opened_; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<size_t> opened_{0}, closed_{0};
  std::thread thread_;
};

TEST(Security, TheOwnerPausesAndCancelsOverTheSocketWhileTcpIsFlooded) {
  TempDir root;
  const fs::path witness = root.path() / "laser";
  Daemon daemon(root.path(), tcpConfig(root.path(), "header_timeout: 120\n" + witnessedLaser(5, witness)));
  daemon.start();
  const long long id = cuttingThreeSheets(daemon);
  ASSERT_NE(id, 0);
  const int port = pagePort(daemon);
  {
    Flood flood(port, 200);
    ASSERT_TRUE(eventually([&] { return flood.opened() >= 200; }, 10));
    // And strangers who send a request's header a piece at a time, never finishing it.
    Flood slowHeaders(port, 40, "GET /api/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n");
    ASSERT_TRUE(eventually([&] { return slowHeaders.opened() >= 40; }, 10));
    // A slow body from a stranger on top: it holds nothing the owner needs.
    const int slow = connectTcp(port);
    const std::string slowStart = "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 1000000\r\n\r\nab";
    ::send(slow, slowStart.data(), slowStart.size(), MSG_NOSIGNAL);
    // A token holder on the same address as the flood (every program on
    // loopback is 127.0.0.1) is served over TCP too: idle strangers give
    // way, and those still sending their header.
    for (int i = 0; i < 20; ++i) {
      const HttpReply listed = overTcp(port, "GET", "/api/jobs", fmt::format("Authorization: Bearer {}\r\n", kToken));
      ASSERT_EQ(listed.status, 200) << listed.head << listed.body;
    }
    // The owner, over the Unix socket, is served at once.
    const CommandResult paused = daemon.client(fmt::format("pause {}", id));
    EXPECT_EQ(paused.status, 0) << paused.err;
    EXPECT_EQ(state(daemon.waitForJob(
                  id, [](const json& j) { return state(j) == "paused"; }, 30)),
              "paused");
    const CommandResult listed = daemon.client("jobs");
    EXPECT_EQ(listed.status, 0) << listed.err;
    const CommandResult cancelled = daemon.client(fmt::format("cancel {}", id));
    EXPECT_EQ(cancelled.status, 0) << cancelled.err;
    EXPECT_EQ(state(daemon.waitForJob(
                  id, [](const json& j) { return state(j) == "cancelled"; }, 30)),
              "cancelled");
    EXPECT_TRUE(readFile(witness).ends_with("off\n")) << readFile(witness);
    // And a stop asked for by a signal ends the daemon, flood or not.
    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.wait(30), 0);
    ::close(slow);
  }
  EXPECT_TRUE(readFile(witness).ends_with("off\n"));
  // Not a word of the daemon's own paths to a stranger, and the refusals were logged as such.
  EXPECT_EQ(readFile(daemon.log()).find("AddressSanitizer"), std::string::npos);
}

// The peak resident memory of a process (VmHWM), in bytes.
size_t peakMemory(pid_t pid) {
  std::ifstream status(fmt::format("/proc/{}/status", pid));
  std::string line;
  while (std::getline(status, line)) {
    if (line.starts_with("VmHWM:")) return std::stoull(line.substr(6)) * 1024;
  }
  return 0;
}

// Sends `head` and then `bytes` of filler on `fd` as fast as the daemon
// takes them, until all is sent, the daemon answers (as curl does, a client
// stops sending at an early reply) or it stops reading; the reply.
RawReply sendHuge(int fd, const std::string& head, size_t bytes, bool chunked = false) {
  ::send(fd, head.data(), head.size(), MSG_NOSIGNAL);
  const std::string piece(1 << 20, 'x');
  const std::string chunk = fmt::format("{:x}\r\n{}\r\n", piece.size(), piece);
  timeval limit{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
  for (size_t sent = 0; sent < bytes; sent += piece.size()) {
    char byte;
    if (::recv(fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT) > 0) break;
    const std::string& what = chunked ? chunk : piece;
    if (::send(fd, what.data(), what.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(what.size())) break;
  }
  return parseReply(rotafab::test::exchange(fd, "", 10));
}

TEST(Security, BodiesNobodyAskedForAreNeverReadIntoMemory) {
  TempDir root;
  Daemon daemon(root.path(), tcpConfig(root.path(), "upload_limit: 1073741824\n"));
  daemon.start();
  const int port = pagePort(daemon);
  ASSERT_EQ(daemon.client("jobs").status, 0);
  const size_t idle = peakMemory(daemon.pid());
  ASSERT_GT(idle, 0u);
  constexpr size_t kMiB = 1 << 20;
  // Four strangers' 250 MiB bodies at once, to a page that takes none.
  std::vector<std::thread> strangers;
  std::vector<int> statuses(4);
  for (int i = 0; i < 4; ++i) {
    strangers.emplace_back([&, i] {
      const int fd = connectTcp(port);
      statuses[i] =
          sendHuge(fd, "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 262144000\r\n\r\n", 250 * kMiB).status;
      ::close(fd);
    });
  }
  for (auto& stranger : strangers) stranger.join();
  for (int status : statuses) EXPECT_EQ(status, 401);
  // A chunked body of 300 MiB with the token, to an action that takes 64 KiB of JSON.
  const int chunkedFd = connectTcp(port);
  const RawReply chunked = sendHuge(chunkedFd,
                                    fmt::format("POST /api/jobs/1/cancel HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: "
                                                "Bearer {}\r\nContent-Type: application/json\r\nTransfer-Encoding: "
                                                "chunked\r\n\r\n",
                                                kToken),
                                    300 * kMiB, true);
  ::close(chunkedFd);
  EXPECT_EQ(chunked.status, 413) << chunked.text.substr(0, 300);
  // A 200 MiB upload by the owner over the socket: streamed to the spool, then refused for its device.
  const std::string preamble =
      "--b\r\nContent-Disposition: form-data; name=\"device\"\r\n\r\nnowhere\r\n"
      "--b\r\nContent-Disposition: form-data; name=\"file\"; filename=\"big.obj\"\r\n\r\n";
  const std::string closing = "\r\n--b--\r\n";
  const size_t meshBytes = 200 * kMiB;
  const int upload = connectUnix(daemon.socket());
  const std::string head = fmt::format(
      "POST /api/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: multipart/form-data; boundary=b\r\nContent-Length: "
      "{}\r\n\r\n{}",
      preamble.size() + meshBytes + closing.size(), preamble);
  ::send(upload, head.data(), head.size(), MSG_NOSIGNAL);
  const std::string piece(kMiB, 'x');
  for (size_t sent = 0; sent < meshBytes; sent += piece.size()) {
    ASSERT_EQ(::send(upload, piece.data(), piece.size(), MSG_NOSIGNAL), static_cast<ssize_t>(piece.size()));
  }
  const RawReply uploaded = parseReply(rotafab::test::exchange(upload, closing, 60));
  ::close(upload);
  EXPECT_EQ(uploaded.status, 400) << uploaded.text.substr(0, 300);
  EXPECT_NE(uploaded.body.value("error", "").find("there is no device nowhere"), std::string::npos) << uploaded.text;
  const size_t peak = peakMemory(daemon.pid());
#ifndef ROTAFAB_SANITIZED
  // (Under AddressSanitizer, freed memory is held back in quarantine and
  // every allocation has red zones: the bound is the program's as built to run.)
  EXPECT_LT(peak, idle + 100 * kMiB) << "idle " << idle / kMiB << " MiB, peak " << peak / kMiB << " MiB";
#endif
  std::printf("rotafabd's peak resident memory: %zu MiB idle, %zu MiB after 1.3 GiB of refused bodies\n", idle / kMiB,
              peak / kMiB);
  // Nothing of the refused upload stays in the spool.
  std::string left;
  for (const auto& entry : fs::recursive_directory_iterator(daemon.stateDir() / "spool")) {
    left += entry.path().string() + " ";
  }
  EXPECT_EQ(left, "");
  EXPECT_EQ(daemon.client("jobs").status, 0);
}

// The mode bits of every file and folder under `folder` that others could use.
std::vector<std::string> readableByOthers(const fs::path& folder) {
  std::vector<std::string> found;
  const auto check = [&](const fs::path& path) {
    struct stat info {};
    // (A file of a submitted `make` folder is linked into the spool, not
    // copied: it is the submitter's own file, under their own mode.)
    if (::lstat(path.c_str(), &info) != 0 || S_ISLNK(info.st_mode) || (S_ISREG(info.st_mode) && info.st_nlink > 1)) {
      return;
    }
    if ((info.st_mode & 077) != 0) found.push_back(fmt::format("{} {:o}", path.string(), info.st_mode & 0777));
  };
  check(folder);
  for (const auto& entry : fs::recursive_directory_iterator(folder)) check(entry.path());
  return found;
}

TEST(Security, TheStateIsTheDaemonUsersAloneWhateverItsUmask) {
  TempDir root;
  // Everything above the state is open to all, so that only the daemon's own modes keep it private.
  for (const fs::path& folder : {root.path(), root.path() / "state", root.path() / "run"}) {
    fs::create_directories(folder);
    ::chmod(folder.c_str(), 0755);
  }
  const fs::path named = root.path() / "sockets";
  fs::create_directories(named);
  ::chmod(named.c_str(), 0755);
  Daemon daemon(root.path(), fmt::format("listen: [\"unix:{}\", \"unix:{}\"]\n", (named / "d.sock").string(),
                                         (root.path() / "run/rotafab/rotafabd.sock").string()));
  const mode_t previous = ::umask(022);
  daemon.start();
  ::umask(previous);
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  EXPECT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  // A mesh the daemon plans itself: its sheets are written by the daemon.
  const long long planned =
      daemon.clientJson("submit " + quoted(kSource / "examples/cube.obj") + " --structure band")["id"];
  EXPECT_EQ(state(daemon.waitForJob(planned, [](const json& j) { return state(j) == "ready"; })), "ready");
  EXPECT_EQ(daemon.client("jobs --server unix:" + (named / "d.sock").string()).status, 0);
  EXPECT_TRUE(fs::exists(daemon.stateDir() / "jobs.sqlite3-wal"));
  EXPECT_EQ(readableByOthers(daemon.stateDir()), std::vector<std::string>{});
  // The folder the user named for the socket is left as they made it; the socket is theirs alone.
  struct stat info {};
  ASSERT_EQ(::stat(named.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0755u);
  ASSERT_EQ(::stat((named / "d.sock").c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 077, 0u);
  // Another account reads nothing of it.
  const passwd* nobody = ::getpwnam("nobody");
  if (nobody == nullptr || ::geteuid() != 0) GTEST_SKIP() << "another account needs root and the user nobody";
  const pid_t child = ::fork();
  if (child == 0) {
    if (::setgid(nobody->pw_gid) != 0 || ::setuid(nobody->pw_uid) != 0) ::_exit(10);
    int readable = 0;
    for (const char* name : {"jobs.sqlite3", "jobs.sqlite3-wal", "rotafabd.log", "rotafabd.json"}) {
      const int fd = ::open((daemon.stateDir() / name).c_str(), O_RDONLY);
      if (fd >= 0) ++readable, ::close(fd);
    }
    if (::opendir(daemon.stateDir().c_str()) != nullptr) ++readable;
    if (connectUnix(named / "d.sock") >= 0) ++readable;
    ::_exit(readable);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "files the account nobody could open";
}

}  // namespace
}  // namespace rotafab::test
