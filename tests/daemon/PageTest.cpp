// The workshop page's side of the daemon, over real TCP as a browser meets
// it: the default loopback listener, the one-time login link and its
// session, the page's files, and the sheets and files the page draws.

#include <arpa/inet.h>
#include <netinet/in.h>

#include "daemon/DaemonSupport.h"

namespace rotafab::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

struct HttpReply {
  int status = 0;
  std::string head, body;
  [[nodiscard]] std::string header(const std::string& name) const {
    const std::string key = "\r\n" + name + ": ";
    const size_t at = head.find(key);
    if (at == std::string::npos) return "";
    const size_t start = at + key.size();
    return head.substr(start, head.find("\r\n", start) - start);
  }
};

// One request on a new TCP connection to 127.0.0.1:port.
HttpReply overTcp(int port, const std::string& method, const std::string& target, const std::string& extraHeaders = "",
                  const std::string& body = "") {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return {};
  }
  const std::string text = rotafab::test::exchange(
      fd, fmt::format("{} {} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nConnection: close\r\n{}Content-Length: {}\r\n\r\n{}",
                      method, target, port, extraHeaders, body.size(), body));
  ::close(fd);
  HttpReply reply;
  if (text.starts_with("HTTP/1.1 ")) reply.status = std::stoi(text.substr(9, 3));
  const size_t split = text.find("\r\n\r\n");
  reply.head = text.substr(0, split);
  if (split != std::string::npos) reply.body = text.substr(split + 4);
  return reply;
}

// The port of the daemon's loopback TCP listener, as rotafabd.json records
// it (written just after the socket answers: waited for).
int pagePort(const Daemon& daemon) {
  int port = 0;
  eventually(
      [&] {
        const json where = json::parse(readFile(daemon.stateDir() / "rotafabd.json"), nullptr, false);
        if (!where.is_object()) return false;
        for (const json& address : where["listen"]) {
          const std::string text = address.get<std::string>();
          if (text.starts_with("tcp://127.0.0.1:")) port = std::stoi(text.substr(16));
        }
        return port > 0;
      },
      10);
  return port;
}

// The session cookie a login link gives ("rotafab_session=..."), or "".
std::string signIn(const Daemon& daemon, int port) {
  const CommandResult link = daemon.client("dashboard --url");
  EXPECT_EQ(link.status, 0) << link.err;
  const std::string prefix = fmt::format("http://127.0.0.1:{}", port);
  EXPECT_TRUE(link.out.starts_with(prefix + "/login?code=")) << link.out;
  const std::string target = link.out.substr(prefix.size(), link.out.find('\n') - prefix.size());
  const HttpReply landed = overTcp(port, "GET", target);
  EXPECT_EQ(landed.status, 303) << landed.head;
  EXPECT_EQ(landed.header("Location"), "/");
  const std::string cookie = landed.header("Set-Cookie");
  EXPECT_NE(cookie.find("HttpOnly"), std::string::npos) << cookie;
  EXPECT_NE(cookie.find("SameSite=Strict"), std::string::npos) << cookie;
  // The same link again opens nothing.
  const HttpReply again = overTcp(port, "GET", target);
  EXPECT_EQ(again.status, 401);
  EXPECT_NE(again.body.find("used already"), std::string::npos) << again.body;
  return cookie.substr(0, cookie.find(';'));
}

TEST(Page, TheDefaultDaemonServesThePageOnLoopbackToASessionOnly) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  const int port = pagePort(daemon);
  ASSERT_GT(port, 0) << readFile(daemon.stateDir() / "rotafabd.json");
  // Nobody gets in without a token or a session: the page says how to get one, the API in its JSON.
  const HttpReply page = overTcp(port, "GET", "/");
  EXPECT_EQ(page.status, 401);
  EXPECT_NE(page.header("Content-Type").find("text/html"), std::string::npos);
  EXPECT_NE(page.body.find("rotafab dashboard"), std::string::npos) << page.body;
  const HttpReply api = overTcp(port, "GET", "/api/jobs");
  EXPECT_EQ(api.status, 401);
  EXPECT_NE(json::parse(api.body, nullptr, false).value("error", "").find("rotafab dashboard"), std::string::npos)
      << api.body;
  EXPECT_EQ(overTcp(port, "GET", "/app/app.js").status, 401);
  EXPECT_EQ(overTcp(port, "GET", "/api/jobs", "Cookie: rotafab_session=forged\r\n").status, 401);
  EXPECT_EQ(overTcp(port, "GET", "/login?code=guessed").status, 401);

  const std::string cookie = signIn(daemon, port);
  ASSERT_TRUE(cookie.starts_with("rotafab_session=")) << cookie;
  const std::string withSession = "Cookie: " + cookie + "\r\n";
  const HttpReply index = overTcp(port, "GET", "/", withSession);
  EXPECT_EQ(index.status, 200);
  EXPECT_NE(index.body.find("/app/app.js"), std::string::npos);
  for (const char* file : {"/app/app.js", "/app/style.css", "/lib/three/build/three.min.js",
                           "/lib/three/examples/js/controls/OrbitControls.js"}) {
    const HttpReply served = overTcp(port, "GET", file, withSession);
    EXPECT_EQ(served.status, 200) << file << ": " << served.body.substr(0, 200);
    EXPECT_GT(served.body.size(), 1000u) << file;
  }
  EXPECT_NE(overTcp(port, "GET", "/app/app.js", withSession).header("Content-Type").find("javascript"),
            std::string::npos);
  // Nothing beyond the page's own files and the three.js it loads.
  for (const char* outside : {"/app/../../CMakeLists.txt", "/lib/three/../../jquery/jquery.js", "/etc/passwd",
                              "/lib/three/package.json", "/app/.hidden.js"}) {
    EXPECT_EQ(overTcp(port, "GET", outside, withSession).status, 404) << outside;
  }
  const HttpReply jobs = overTcp(port, "GET", "/api/jobs", withSession);
  EXPECT_EQ(jobs.status, 200);
  EXPECT_TRUE(json::parse(jobs.body, nullptr, false).contains("jobs")) << jobs.body;
  // A session's action sent by another site's page is refused; the page's own goes through.
  const HttpReply forged =
      overTcp(port, "POST", "/api/jobs/1/cancel", withSession + "Origin: http://evil.example\r\n", "{}");
  EXPECT_EQ(forged.status, 403);
  EXPECT_NE(forged.body.find("not from another site"), std::string::npos) << forged.body;
  const HttpReply own = overTcp(port, "POST", "/api/jobs/1/cancel",
                                withSession + fmt::format("Origin: http://127.0.0.1:{}\r\n", port), "{}");
  EXPECT_EQ(own.status, 404) << own.body;  // no job 1: refused by the queue, not the guard
  // A session cannot mint further links; a login link is for this machine's user or a token's holder.
  EXPECT_EQ(overTcp(port, "POST", "/api/sessions", withSession, "{}").status, 403);
}

TEST(Page, TwoDaemonsWithTheDefaultsBothServeThePage) {
  TempDir first, second;
  Daemon one(first.path()), two(second.path());
  one.start();
  two.start();
  const int a = pagePort(one), b = pagePort(two);
  EXPECT_GT(a, 0);
  EXPECT_GT(b, 0);
  EXPECT_NE(a, b);
  // Each daemon's link is for its own port.
  const CommandResult link = two.client("dashboard --url");
  EXPECT_EQ(link.status, 0) << link.err;
  EXPECT_TRUE(link.out.starts_with(fmt::format("http://127.0.0.1:{}/login?code=", b))) << link.out;
}

TEST(Page, WithoutATcpListenerTheDashboardSaysWhatToAdd) {
  TempDir root;
  Daemon daemon(root.path(), fmt::format("listen: [unix:{}]\n", (root.path() / "run/rotafab/rotafabd.sock").string()));
  daemon.start();
  const CommandResult link = daemon.client("dashboard --url");
  EXPECT_EQ(link.status, 1);
  EXPECT_NE(link.err.find("add tcp://127.0.0.1:8730 to listen"), std::string::npos) << link.err;
  EXPECT_EQ(std::count(link.err.begin(), link.err.end(), '\n'), 1) << link.err;
}

TEST(Page, ASheetIsItsStrokesInTheOrderTheLaserBurnsThem) {
  TempDir root;
  Daemon daemon(root.path(), "devices: [{name: laser1, machine: grbl-diode-400, uri: \"sim:grbl?speed=400\"}]\n");
  daemon.start();
  const CommandResult submitted =
      daemon.client("submit " + quoted(kSource / "examples/cube.obj") + " --structure band --evaluations 1 --json");
  ASSERT_EQ(submitted.status, 0) << submitted.err;
  const long long id = json::parse(submitted.out)["id"];
  const json ready =
      daemon.waitForJob(id, [](const json& job) { return job["state"] != "queued" && job["state"] != "planning"; });
  ASSERT_EQ(ready["state"], "ready") << ready.dump();
  const RawReply sheet = daemon.get(fmt::format("/api/jobs/{}/sheets/1", id));
  ASSERT_EQ(sheet.status, 200) << sheet.text;
  const json& strokes = sheet.body["strokes"];
  ASSERT_GT(strokes.size(), 10u);
  // Every stroke drawn in its operation's colour of the machine's table; etch, score, then cut.
  std::vector<std::string> order;
  for (const json& stroke : strokes) {
    const std::string operation = stroke["operation"];
    EXPECT_TRUE(sheet.body["colours"].contains(operation)) << operation;
    EXPECT_GE(stroke["points"].size(), 2u);
    if (order.empty() || order.back() != operation) order.push_back(operation);
  }
  EXPECT_EQ(order.back(), "cut");
  EXPECT_GT(sheet.body["seconds"].get<double>(), 1.0);
  // What the cut then counts is these strokes, one by one.
  ASSERT_EQ(daemon.client(fmt::format("start {}", id)).status, 0);
  const json done = daemon.waitForJob(id, [](const json& job) { return job["state"] == "done"; });
  ASSERT_EQ(done["state"], "done") << done.dump();
  EXPECT_EQ(done["strokes"].get<size_t>(), strokes.size());
  EXPECT_EQ(done["stroke"].get<size_t>(), strokes.size());
  // The files the page shows, and nothing else of the spool.
  const RawReply preview = daemon.get(fmt::format("/api/jobs/{}/files/sheet-001.preview.svg", id));
  EXPECT_EQ(preview.status, 200);
  EXPECT_NE(preview.text.find("Content-Type: image/svg+xml"), std::string::npos);
  EXPECT_NE(preview.text.find("<svg"), std::string::npos);
  const RawReply obj = daemon.get(fmt::format("/api/jobs/{}/files/structure.obj", id));
  EXPECT_EQ(obj.status, 200);
  EXPECT_NE(obj.text.find("\ng panel-6\n"), std::string::npos);
  for (const char* name : {"cube.obj", "..%2Fjobs.sqlite", "sheet-001.eps", "manifest.json.tmp"}) {
    const RawReply refused = daemon.get(fmt::format("/api/jobs/{}/files/{}", id, name));
    EXPECT_EQ(refused.status, 404) << name;
  }
  EXPECT_EQ(daemon.get(fmt::format("/api/jobs/{}/sheets/2", id)).status, 404);
  EXPECT_NE(daemon.get(fmt::format("/api/jobs/{}/sheets/2", id)).body.value("error", "").find("sheets 1 to 1"),
            std::string::npos);
}

}  // namespace
}  // namespace rotafab::test
