// The workshop page's side of the daemon, over real TCP as a browser meets
// it: the default loopback listener, the one-time login link and its
// session, the page's files, and the sheets and files the page draws.

#include "daemon/DaemonSupport.h"

namespace rotafab::test {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// The session secret a login link gives the page (in the address's
// fragment, which a browser never sends), or "".
std::string signIn(const Daemon& daemon, int port) {
  const CommandResult link = daemon.client("dashboard --url");
  EXPECT_EQ(link.status, 0) << link.err;
  const std::string prefix = fmt::format("http://127.0.0.1:{}", port);
  EXPECT_TRUE(link.out.starts_with(prefix + "/login?code=")) << link.out;
  const std::string target = link.out.substr(prefix.size(), link.out.find('\n') - prefix.size());
  const HttpReply landed = overTcp(port, "GET", target);
  EXPECT_EQ(landed.status, 303) << landed.head;
  const std::string location = landed.header("Location");
  EXPECT_TRUE(location.starts_with("/#session=")) << location;
  EXPECT_EQ(landed.header("Set-Cookie"), "");  // nothing a browser would send by itself
  // The same link again opens nothing: the page is told so.
  const HttpReply again = overTcp(port, "GET", target);
  EXPECT_EQ(again.status, 303);
  EXPECT_EQ(again.header("Location"), "/#signin=used");
  return location.starts_with("/#session=") ? location.substr(10) : "";
}

TEST(Page, TheDefaultDaemonServesThePageOnLoopbackAndItsQueueToASessionOnly) {
  TempDir root;
  Daemon daemon(root.path());
  daemon.start();
  const int port = pagePort(daemon);
  ASSERT_GT(port, 0) << readFile(daemon.stateDir() / "rotafabd.json");
  // The page's files are the same for everyone; no other page may frame them.
  const HttpReply index = overTcp(port, "GET", "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_NE(index.header("Content-Type").find("text/html"), std::string::npos);
  EXPECT_NE(index.body.find("/app/app.js"), std::string::npos);
  EXPECT_NE(index.body.find("rotafab dashboard"), std::string::npos);  // what to do without a session
  EXPECT_EQ(index.header("X-Frame-Options"), "DENY");
  EXPECT_EQ(index.header("Content-Security-Policy"), "frame-ancestors 'none'");
  EXPECT_EQ(index.header("X-Content-Type-Options"), "nosniff");
  for (const char* file : {"/app/app.js", "/app/style.css", "/lib/three/build/three.min.js",
                           "/lib/three/examples/js/controls/OrbitControls.js"}) {
    const HttpReply served = overTcp(port, "GET", file);
    EXPECT_EQ(served.status, 200) << file << ": " << served.body.substr(0, 200);
    EXPECT_GT(served.body.size(), 1000u) << file;
  }
  EXPECT_NE(overTcp(port, "GET", "/app/app.js").header("Content-Type").find("javascript"), std::string::npos);
  EXPECT_EQ(overTcp(port, "GET", "/favicon.ico").status, 204);
  // Nothing beyond the page's own files and the three.js it loads: a path
  // that climbs above the root is malformed, one that leaves the page's
  // folders is the API's (a token is asked for), one inside them unknown.
  for (const auto& [outside, status] :
       std::vector<std::pair<std::string, int>>{{"/app/../../CMakeLists.txt", 400},
                                                {"/lib/three/../../jquery/jquery.js", 401},
                                                {"/etc/passwd", 401},
                                                {"/lib/three/package.json", 404},
                                                {"/app/.hidden.js", 404},
                                                {"/app/%2e%2e/%2e%2e/CMakeLists.txt", 400},
                                                {"/app/..%2f..%2fCMakeLists.txt", 400}}) {
    const HttpReply reply = overTcp(port, "GET", outside);
    EXPECT_EQ(reply.status, status) << outside;
    EXPECT_EQ(reply.body.find("project("), std::string::npos) << outside;
  }
  // Nobody reaches the queue without a token or a session.
  const HttpReply api = overTcp(port, "GET", "/api/jobs");
  EXPECT_EQ(api.status, 401);
  EXPECT_NE(json::parse(api.body, nullptr, false).value("error", "").find("rotafab dashboard"), std::string::npos)
      << api.body;
  EXPECT_EQ(overTcp(port, "GET", "/api/jobs", "Authorization: Bearer forged\r\n").status, 401);
  EXPECT_EQ(overTcp(port, "GET", "/api/events?session=forged").status, 401);

  const std::string secret = signIn(daemon, port);
  ASSERT_EQ(secret.size(), 64u) << secret;
  const std::string bearer = "Authorization: Bearer " + secret + "\r\n";
  const HttpReply jobs = overTcp(port, "GET", "/api/jobs", bearer);
  EXPECT_EQ(jobs.status, 200);
  EXPECT_TRUE(json::parse(jobs.body, nullptr, false).contains("jobs")) << jobs.body;
  // A cookie carrying the secret is not a way in: a browser would send it to any port of this host.
  EXPECT_EQ(overTcp(port, "GET", "/api/jobs", "Cookie: rotafab_session=" + secret + "\r\n").status, 401);
  // The event stream, which cannot send a header, takes it in its address.
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  const std::string request =
      fmt::format("GET /api/events?session={} HTTP/1.1\r\nHost: 127.0.0.1:{}\r\n\r\n", secret, port);
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  char head[64] = {};
  EXPECT_GT(::recv(fd, head, sizeof head - 1, 0), 12);
  EXPECT_TRUE(std::string(head).starts_with("HTTP/1.1 200")) << head;
  ::close(fd);
  // A session cannot mint further links; a login link is for this machine's user or a token's holder.
  EXPECT_EQ(overTcp(port, "POST", "/api/sessions", bearer + "Content-Type: application/json\r\n", "{}").status, 403);
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
  // What the plan warned of is the job's, as `make --json` gives it, in the submitter's words.
  ASSERT_EQ(ready["summary"]["warnings"].size(), 1u) << ready.dump();
  EXPECT_TRUE(ready["summary"]["warnings"][0].get<std::string>().starts_with("cube.obj: 12 bands are too narrow"))
      << ready["summary"]["warnings"][0];
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
  for (const auto& [name, status] : std::vector<std::pair<std::string, int>>{{"cube.obj", 404},
                                                                             {"..%2Fjobs.sqlite", 400},
                                                                             {"..%2Fspool", 400},
                                                                             {"sheet-001.eps", 404},
                                                                             {"manifest.json.tmp", 404}}) {
    const RawReply refused = daemon.get(fmt::format("/api/jobs/{}/files/{}", id, name));
    EXPECT_EQ(refused.status, status) << name;
  }
  EXPECT_EQ(daemon.get(fmt::format("/api/jobs/{}/sheets/2", id)).status, 404);
  EXPECT_NE(daemon.get(fmt::format("/api/jobs/{}/sheets/2", id)).body.value("error", "").find("sheets 1 to 1"),
            std::string::npos);
}

}  // namespace
}  // namespace rotafab::test
