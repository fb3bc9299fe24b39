// The daemon's edge, as a library: the one spelling of a request's path,
// the gate that decides from a request's header alone who may ask what and
// with which body, the checks of what a request brings, and the multipart
// reader that streams an upload to its file (docs/SECURITY.md).

#include <gtest/gtest.h>

#include <random>

#include "daemon/service/AccessGate.h"
#include "daemon/service/ApiError.h"
#include "daemon/service/ApiInput.h"
#include "daemon/service/DaemonConfig.h"
#include "daemon/service/Multipart.h"
#include "daemon/service/RequestTarget.h"
#include "daemon/service/UploadForm.h"
#include "support/TestSupport.h"

namespace rotafab::service {
namespace {

using nlohmann::json;
using test::TempDir;
namespace http = boost::beast::http;

// The status of the ApiError `call` throws; 0 when it throws none.
template <typename Call>
int refusal(Call&& call) {
  try {
    call();
  } catch (const ApiError& error) {
    return error.status;
  }
  return 0;
}

TEST(RequestTarget, EverySpellingOfAPathIsReadAsOne) {
  for (const char* spelling :
       {"/api/jobs", "//api/jobs", "/api//jobs/", "/./api/jobs", "/x/../api/jobs", "/%61pi/jobs",
        "/%61%70%69/%6A%6F%62%73", "/api/jobs/.", "/api/jobs/x/..", "/api/./jobs?x=1", "///api///jobs///"}) {
    const RequestTarget target = parseTarget(spelling);
    EXPECT_EQ(target.path(), "/api/jobs") << spelling;
    EXPECT_EQ(target.parts, (std::vector<std::string>{"api", "jobs"})) << spelling;
  }
  EXPECT_EQ(parseTarget("/").path(), "/");
  EXPECT_EQ(parseTarget("/api/..").path(), "/");
  EXPECT_EQ(parseTarget("/api/events?session=a%20b&x").query, "session=a%20b&x");
  // What cannot be read one way only is refused, each saying why.
  for (const char* malformed :
       {"", "api/jobs", "*", "http://127.0.0.1:8730/api/jobs", "/..", "/api/../../etc/passwd", "/%2Fapi/jobs",
        "/api%2fjobs", "/api%5Cjobs", "/api/%00", "/api/jobs%0a", "/%zzapi", "/api/%4", "/api#jobs", "/%2e%2e/x"}) {
    EXPECT_EQ(refusal([&] { (void)parseTarget(malformed); }), 400) << malformed;
  }
  std::string deep;
  for (int i = 0; i < 65; ++i) deep += "/a";
  EXPECT_EQ(refusal([&] { (void)parseTarget(deep); }), 400);
  EXPECT_EQ(queryValue("a=1&session=s%2B1+2&b", "session"), "s+1 2");
  EXPECT_EQ(queryValue("a=1", "session"), "");
  EXPECT_EQ(queryValue("se%73sion=x", "session"), "x");
}

// A sample path of every route the daemon answers, its method, and the body it takes.
struct Sample {
  std::string path;
  http::verb method;
  Route route;
};
std::vector<Sample> everyRoute() {
  std::vector<Sample> samples{
      {"/", http::verb::get, Route::PageIndex},
      {"/app/app.js", http::verb::get, Route::PageFile},
      {"/lib/three/build/three.min.js", http::verb::get, Route::PageLibrary},
      {"/login", http::verb::get, Route::Login},
      {"/favicon.ico", http::verb::get, Route::Favicon},
      {"/api", http::verb::get, Route::About},
      {"/api/sessions", http::verb::post, Route::Sessions},
      {"/api/devices", http::verb::get, Route::Devices},
      {"/api/events", http::verb::get, Route::Events},
      {"/api/jobs", http::verb::get, Route::Jobs},
      {"/api/jobs", http::verb::post, Route::Jobs},
      {"/api/jobs/1", http::verb::get, Route::Job},
      {"/api/jobs/1/manifest", http::verb::get, Route::JobManifest},
      {"/api/jobs/1/files/manifest.json", http::verb::get, Route::JobFile},
      {"/api/jobs/1/sheets/1", http::verb::get, Route::JobSheet},
  };
  for (const char* action : {"cancel", "pause", "resume", "start", "next", "move"}) {
    samples.push_back({fmt::format("/api/jobs/1/{}", action), http::verb::post, Route::JobAction});
  }
  return samples;
}

// The spellings an attacker tries of a path that all mean it.
std::vector<std::string> sameMeaning(const std::string& path) {
  const std::string rest = path.substr(1);
  std::vector<std::string> spellings{path, "/" + path, "/./" + rest, "/x/../" + rest, path + "/"};
  if (!rest.empty()) spellings.push_back(fmt::format("/%{:02X}{}", static_cast<int>(rest[0]), rest.substr(1)));
  return spellings;
}

// Spellings that mean another path, or nothing: never what `path` means.
std::vector<std::string> otherMeaning(const std::string& path) {
  std::string upper = path;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  std::vector<std::string> spellings{"/%2F" + path.substr(1), path + "%00", "/.." + path};
  if (upper != path) spellings.push_back(upper);
  return spellings;
}

// A request over loopback TCP, as a client sends it with a JSON body.
RequestHead overLoopback(http::verb method, std::string_view target, std::string_view authorization) {
  RequestHead head;
  head.method = method;
  head.target = target;
  head.host = "127.0.0.1:8730";
  head.authorization = authorization;
  head.contentType = "application/json";
  head.contentLength = method == http::verb::post ? 2 : 0;
  return head;
}

TEST(AccessGate, EveryRouteInEverySpellingAsksForATokenUnlessItIsThePagesOwn) {
  DaemonConfig config;
  config.tokens.push_back({"alice", hashToken("right-token", "5a17")});
  AccessGate gate(config);
  const Listener tcp{false, true};
  for (const Sample& sample : everyRoute()) {
    const bool open = endpointFor(sample.route, sample.method)->open;
    for (const std::string& spelling : sameMeaning(sample.path)) {
      for (const char* authorization : {"", "Bearer wrong-token", "Bearer right-token", "right-token"}) {
        const RequestHead head = overLoopback(sample.method, spelling, authorization);
        const bool known = std::string_view(authorization) == "Bearer right-token";
        const std::string what =
            fmt::format("{} {} with \"{}\"", std::string(http::to_string(sample.method)), spelling, authorization);
        if (!known && !open) {
          EXPECT_EQ(refusal([&] { gate.admit(head, tcp, std::nullopt); }), 401) << what;
          continue;
        }
        try {
          const Admission admitted = gate.admit(head, tcp, std::nullopt);
          EXPECT_EQ(admitted.route.route, sample.route) << what;
          EXPECT_EQ(admitted.target.path(), parseTarget(sample.path).path()) << what;
          EXPECT_EQ(admitted.caller.has_value(), known) << what;
          if (known) {
            EXPECT_EQ(admitted.caller->name, "alice");
          }
        } catch (const ApiError& error) {
          ADD_FAILURE() << what << ": " << error.status << " " << error.what();
        }
      }
    }
    // A spelling that means something else never reaches this route.
    for (const std::string& spelling : otherMeaning(sample.path)) {
      for (const char* authorization : {"", "Bearer right-token"}) {
        const RequestHead head = overLoopback(sample.method, spelling, authorization);
        try {
          const Admission admitted = gate.admit(head, tcp, std::nullopt);
          EXPECT_NE(admitted.route.route, sample.route) << spelling;
          EXPECT_TRUE(admitted.caller || endpointFor(admitted.route.route, sample.method)->open) << spelling;
        } catch (const ApiError& error) {
          EXPECT_TRUE(error.status == 400 || error.status == 401 || error.status == 404)
              << spelling << ": " << error.status;
          if (*authorization == '\0') {
            EXPECT_NE(error.status, 404) << spelling << ": no route told a stranger";
          }
        }
      }
    }
  }
  // Over the Unix socket, the peer is who its credentials say; without them nobody.
  RequestHead head;
  head.method = http::verb::get;
  head.target = "//api/jobs";
  EXPECT_EQ(gate.admit(head, Listener{true, false}, Caller{"bob", false}).caller->name, "bob");
  EXPECT_EQ(refusal([&] { gate.admit(head, Listener{true, false}, std::nullopt); }), 401);
}

TEST(AccessGate, ARequestAnotherSitesPageCanSendChangesNothing) {
  DaemonConfig config;
  config.tokens.push_back({"alice", hashToken("right-token", "5a17")});
  config.origins.push_back("https://rotafab.lab.example");
  AccessGate gate(config);
  const Listener tcp{false, true};
  const auto startWith = [&](std::string_view contentType, std::string_view origin, std::string_view site,
                             std::string_view host = "127.0.0.1:8730") {
    RequestHead head;
    head.method = http::verb::post;
    head.target = "//api/jobs/1/start";
    head.host = host;
    head.authorization = "Bearer right-token";
    head.contentType = contentType;
    head.origin = origin;
    head.fetchSite = site;
    head.contentLength = 2;
    return refusal([&] { gate.admit(head, tcp, std::nullopt); });
  };
  // What a form or fetch of another page may send without asking first.
  EXPECT_EQ(startWith("text/plain", "", ""), 415);
  EXPECT_EQ(startWith("application/x-www-form-urlencoded", "", ""), 415);
  EXPECT_EQ(startWith("multipart/form-data; boundary=b", "", ""), 415);
  EXPECT_EQ(startWith("application/json", "http://evil.example", ""), 403);
  EXPECT_EQ(startWith("application/json", "null", ""), 403);
  EXPECT_EQ(startWith("application/json", "http://127.0.0.1:8730", "cross-site"), 403);
  EXPECT_EQ(startWith("application/json", "http://127.0.0.1:8730", "same-site"), 403);
  // A page served under another name (DNS rebinding) is refused by its Host.
  EXPECT_EQ(startWith("application/json", "http://evil.example:8730", "same-origin", "evil.example:8730"), 421);
  // An action without arguments needs no body, and so no type.
  EXPECT_EQ(refusal([&] {
              RequestHead head;
              head.method = http::verb::post;
              head.target = "/api/jobs/1/pause";
              head.host = "127.0.0.1:8730";
              head.authorization = "Bearer right-token";
              head.contentLength = 0;
              gate.admit(head, tcp, std::nullopt);
            }),
            0);
  // The page's own requests, and a client's without Origin.
  EXPECT_EQ(startWith("application/json", "http://127.0.0.1:8730", "same-origin"), 0);
  EXPECT_EQ(startWith("Application/JSON; charset=utf-8", "", ""), 0);
  EXPECT_EQ(startWith("application/json", "http://localhost:8730", "same-origin", "localhost:8730"), 0);
  // Behind a reverse proxy, the page's address as configured.
  EXPECT_EQ(startWith("application/json", "https://rotafab.lab.example", "same-origin", "rotafab.lab.example"), 0);
  EXPECT_EQ(startWith("application/json", "https://rotafab.lab.example.evil", "", "rotafab.lab.example"), 403);
}

// The gate's answer to a request's header as it comes over a loopback TCP
// listener (-1: Beast itself refused it as malformed).
int admitBytes(AccessGate& gate, const std::string& bytes) {
  http::request_parser<http::empty_body> parser;
  parser.eager(false);
  boost::beast::error_code error;
  parser.put(boost::asio::buffer(bytes), error);
  if (error && error != http::error::need_more) return -1;
  if (!parser.is_header_done()) return -1;
  return refusal([&] { gate.admit(requestHead(parser), Listener{false, true}, std::nullopt); });
}

TEST(AccessGate, AHeaderThatTwoReadersCouldReadTwoWaysIsRefused) {
  DaemonConfig config;
  config.tokens.push_back({"alice", hashToken("right-token", "5a17")});
  AccessGate gate(config);
  const std::string start = "POST /api/jobs/1/cancel HTTP/1.1\r\n";
  const std::string host = "Host: 127.0.0.1:8730\r\n";
  const std::string token = "Authorization: Bearer right-token\r\n";
  const std::string json = "Content-Type: application/json\r\n";
  EXPECT_EQ(admitBytes(gate, start + host + token + json + "Content-Length: 2\r\n\r\n"), 0);
  EXPECT_EQ(admitBytes(gate, start + host + token + json + "Transfer-Encoding: chunked\r\n\r\n"), 0);
  // The same field twice: which one a proxy and the daemon each take is a guess.
  EXPECT_EQ(admitBytes(gate, start + host + "Host: evil.example\r\n" + token + "\r\n"), 400);
  EXPECT_EQ(admitBytes(gate, start + host + token + "Authorization: Bearer wrong\r\n\r\n"), 400);
  EXPECT_EQ(admitBytes(gate, start + host + token + "Origin: http://127.0.0.1:8730\r\nOrigin: http://evil\r\n\r\n"),
            400);
  EXPECT_EQ(admitBytes(gate, start + host + token + json + json + "Content-Length: 2\r\n\r\n"), 400);
  EXPECT_EQ(
      admitBytes(gate, start + host + token + "Sec-Fetch-Site: same-origin\r\nSec-Fetch-Site: cross-site\r\n\r\n"),
      400);
  // A coding other than chunked alone: not guessed at.
  for (const std::string coding : {"identity", "xchunked", "chunked, identity", "gzip, chunked", "chunked, chunked"}) {
    const int status = admitBytes(gate, start + host + token + json + "Transfer-Encoding: " + coding + "\r\n\r\n");
    EXPECT_TRUE(status == 501 || status == 400 || status == -1) << coding << ": " << status;
  }
  RequestHead both;
  both.method = http::verb::post;
  both.target = "/api/jobs/1/cancel";
  both.host = "127.0.0.1";
  both.authorization = "Bearer right-token";
  both.contentType = "application/json";
  both.transferEncoding = "chunked";
  both.chunked = true;
  both.contentLength = 2;
  EXPECT_EQ(refusal([&] { gate.admit(both, Listener{false, true}, std::nullopt); }), 400);
  // Only this machine's loopback names, with at most a port after them.
  const std::string get = "GET /api/jobs HTTP/1.1\r\n" + token;
  for (const std::string name :
       {"127.0.0.1:8730", "127.0.0.1", "localhost:8730", "LOCALHOST", "[::1]:8730", "127.8.9.10:1"}) {
    EXPECT_EQ(admitBytes(gate, get + "Host: " + name + "\r\n\r\n"), 0) << name;
  }
  for (const std::string name :
       {"evil.localhost:8730", "127.1:8730", "127.0.0.1:8730junk", "127.0.0.1.evil.example", "0x7f.0.0.1",
        "127.0.0.256", "[::1]junk", "localhost:", "127.0.0.1:99999999", "[::2]:8730"}) {
    EXPECT_EQ(admitBytes(gate, get + "Host: " + name + "\r\n\r\n"), 421) << name;
  }
}

TEST(AccessGate, ABodyIsJudgedByItsHeaderBeforeAByteOfItIsRead) {
  DaemonConfig config;
  config.uploadLimit = 1000;
  AccessGate gate(config);
  const Caller owner{"root", false};
  const auto admit = [&](http::verb method, std::string_view target, std::string_view type,
                         std::optional<uint64_t> length, bool chunked = false) {
    RequestHead head;
    head.method = method;
    head.target = target;
    head.contentType = type;
    head.contentLength = length;
    head.chunked = chunked;
    return gate.admit(head, Listener{true, false}, owner);
  };
  EXPECT_EQ(refusal([&] { admit(http::verb::get, "/api/jobs", "", 5); }), 400);
  EXPECT_EQ(refusal([&] { admit(http::verb::get, "/api/jobs", "", std::nullopt, true); }), 400);
  EXPECT_EQ(refusal([&] { admit(http::verb::post, "/api/jobs", "application/json", kJsonBodyLimit + 1); }), 413);
  EXPECT_EQ(refusal([&] { admit(http::verb::post, "/api/jobs", "multipart/form-data; boundary=b", 1001); }), 413);
  EXPECT_EQ(refusal([&] { admit(http::verb::post, "/api/jobs", "multipart/form-data", 10); }), 400);
  EXPECT_EQ(refusal([&] { admit(http::verb::delete_, "/api/jobs", "", std::nullopt); }), 405);
  EXPECT_EQ(refusal([&] { admit(http::verb::post, "/api/jobs/1/explode", "application/json", 2); }), 404);
  // `curl -d '{"from_sheet": 3}'` over the socket, which no page reaches: read as JSON.
  EXPECT_EQ(admit(http::verb::post, "/api/jobs/1/resume", "application/x-www-form-urlencoded", 17).body,
            BodyKind::Json);
  const Admission form = admit(http::verb::post, "/api/jobs", "multipart/form-data; boundary=b", 1000);
  EXPECT_EQ(form.body, BodyKind::JsonOrForm);
  EXPECT_EQ(form.boundary, "b");
  EXPECT_EQ(form.bodyLimit, 1000u);
  // A chunked body's size is not known from its header: the reader stops at the limit.
  const Admission chunked = admit(http::verb::post, "/api/jobs/3/cancel", "application/json", std::nullopt, true);
  EXPECT_EQ(chunked.body, BodyKind::Json);
  EXPECT_EQ(chunked.bodyLimit, kJsonBodyLimit);
  EXPECT_EQ(chunked.route.job, "3");
  EXPECT_EQ(chunked.route.name, "cancel");
}

TEST(AccessGate, ASessionIsGivenOnceForALoginCodeAndTakenInTheEventStreamsAddressOnly) {
  DaemonConfig config;
  config.tokens.push_back({"alice", hashToken("right-token", "5a17")});
  AccessGate gate(config);
  const std::string code = gate.newLoginCode("root");
  const auto secret = gate.openSession(code);
  ASSERT_TRUE(secret);
  EXPECT_FALSE(gate.openSession(code));
  const auto asking = [&](std::string target, std::string authorization) -> std::optional<Caller> {
    RequestHead head;
    head.method = http::verb::get;
    head.target = target;
    head.host = "[::1]:8730";
    head.authorization = authorization;
    return gate.admit(head, Listener{false, true}, std::nullopt).caller;
  };
  EXPECT_EQ(asking("/api/jobs", "Bearer " + *secret)->name, "root");
  EXPECT_TRUE(asking("/api/jobs", "Bearer " + *secret)->bySession);
  EXPECT_EQ(asking("/api/events?session=" + *secret, "")->name, "root");
  // A token is never taken from an address (they end up in histories and logs), nor a session elsewhere.
  EXPECT_EQ(refusal([&] { asking("/api/events?session=right-token", ""); }), 401);
  EXPECT_EQ(refusal([&] { asking("/api/jobs?session=" + *secret, ""); }), 401);
  EXPECT_EQ(refusal([&] { asking("/api/jobs?token=right-token", ""); }), 401);
}

TEST(ApiInput, NumbersAreCheckedAgainstTheirRangeAndNeverWrapped) {
  EXPECT_EQ(wholeNumber(json(5), kPriorityField), 5);
  EXPECT_EQ(wholeNumber(json("-7"), kPriorityField), -7);
  for (const json& bad : {json(2147483648LL), json(-2147483649LL), json(1e300), json(1.5), json("12abc"), json(""),
                          json(true), json(nullptr), json(18446744073709551615ULL)}) {
    try {
      wholeNumber(bad, kPriorityField);
      ADD_FAILURE() << "accepted " << bad.dump();
    } catch (const ApiError& error) {
      EXPECT_EQ(error.status, 400);
      EXPECT_STREQ(error.what(), "priority: expected a whole number from -1000000 to 1000000");
    }
  }
  EXPECT_EQ(refusal([&] { wholeNumber(json(4294967297LL), kFromSheetField); }), 400);
  EXPECT_EQ(refusal([&] { wholeNumber(json(0), kFromSheetField); }), 400);
  // (JSON text's 0 is read as an unsigned number: checked against the same least.)
  EXPECT_EQ(refusal([&] { wholeNumber(json::parse("0"), kFromSheetField); }), 400);
  EXPECT_EQ(refusal([&] { checkedActionArguments("resume", json::parse(R"({"from_sheet": 0})")); }), 400);
  EXPECT_FALSE(wholeNumberIn("4294967297", kSheetField));
  EXPECT_FALSE(wholeNumberIn("9007199254740992", kJobField));
  EXPECT_EQ(wholeNumberIn("9007199254740991", kJobField), kLargestJobId);
  EXPECT_FALSE(wholeNumberIn("+1", kJobField));
  EXPECT_FALSE(wholeNumberIn(" 1", kJobField));
  // Each action takes its own fields only.
  EXPECT_EQ(checkedActionArguments("resume", json{{"from_sheet", 3}}), (json{{"from_sheet", 3}}));
  EXPECT_EQ(refusal([&] { checkedActionArguments("resume", json{{"from_sheet", 4294967297LL}}); }), 400);
  EXPECT_EQ(refusal([&] { checkedActionArguments("cancel", json{{"force", true}}); }), 400);
  EXPECT_EQ(refusal([&] { checkedActionArguments("move", json{{"priority", 2147483648LL}}); }), 400);
  EXPECT_EQ(refusal([&] { checkedActionArguments("start", json::array()); }), 400);
}

TEST(ApiInput, AFileNameIsCleanedBeforeItNamesAFileAJobOrALogLine) {
  EXPECT_EQ(cleanFileName("bunny.obj"), "bunny.obj");
  EXPECT_EQ(cleanFileName("C:\\Users\\me\\bunny.obj"), "bunny.obj");
  EXPECT_EQ(cleanFileName("../../etc/passwd"), "passwd");
  EXPECT_EQ(cleanFileName("a\nb.obj"), "ab.obj");
  EXPECT_EQ(cleanFileName(std::string("a\0b.obj", 7)), "ab.obj");
  EXPECT_EQ(cleanFileName("\x1b[31mred.obj"), "[31mred.obj");
  EXPECT_EQ(cleanFileName("evil\u202Ejbo.exe"), "eviljbo.exe");  // no right-to-left override
  EXPECT_EQ(cleanFileName("zero\u200Bwidth.obj"), "zerowidth.obj");
  // Every other invisible character: Mongolian vowel separator, tags, line and paragraph separators.
  EXPECT_EQ(cleanFileName("a\u180Eb\U000E0041\U000E007Fc\u2028d\u2029e.obj"), "abcde.obj");
  EXPECT_EQ(cleanFileName("\u2066iso\u2069late\uFFF9.obj"), "isolate.obj");
  EXPECT_EQ(cleanFileName("caf\xc3\xa9.obj"), "caf\xc3\xa9.obj");
  EXPECT_EQ(cleanFileName("bad\xff\xfe.obj"), "bad.obj");
  EXPECT_EQ(cleanFileName(".."), "");
  EXPECT_EQ(cleanFileName("\n\n"), "");
  const std::string longName = cleanFileName(std::string(300, 'a') + ".obj");
  EXPECT_EQ(longName.size(), kLongestFileName);
  EXPECT_TRUE(longName.ends_with("a.obj"));
  // Cut between characters, never inside one.
  std::string accents;
  for (int i = 0; i < 80; ++i) accents += "\xc3\xa9";
  const std::string cut = cleanFileName(accents + ".stl");
  EXPECT_LE(cut.size(), kLongestFileName);
  EXPECT_EQ(cleanFileName(cut), cut);
  EXPECT_EQ(shownText("line\nbreak\u202E", 100), "linebreak");
  EXPECT_EQ(refusal([&] { checkedText(json("laser\n1"), "device"); }), 400);
  EXPECT_EQ(refusal([&] { checkedText(json("a\u202Eb"), "device"); }), 400);
  EXPECT_EQ(refusal([&] { checkedText(json(std::string(65, 'a')), "device", 64); }), 400);
}

TEST(ApiInput, AnErrorNamesAFileButNeverWhereTheDaemonKeepsIt) {
  const std::vector<std::string> folders{"/var/lib/rotafab", "/srv/spool"};
  EXPECT_EQ(withoutDaemonPaths("/var/lib/rotafab/spool/job-1/cube.obj: face 3 has 2 corners", folders),
            "cube.obj: face 3 has 2 corners");
  EXPECT_EQ(withoutDaemonPaths("cannot write '/srv/spool/job-2/sheet-001.svg' (No space left on device)", folders),
            "cannot write 'sheet-001.svg' (No space left on device)");
  EXPECT_EQ(withoutDaemonPaths("/var/lib/rotafab: Permission denied", folders),
            "the daemon's folder: Permission denied");
  EXPECT_EQ(withoutDaemonPaths("/home/me/cube.obj: not found", folders), "/home/me/cube.obj: not found");
}

// Collects what a MultipartReader tells its parts.
struct Collected : MultipartReader::Parts {
  std::vector<FormPart> parts;
  void begin(const FormPartHead& head) override { parts.push_back({head.name, head.fileName, ""}); }
  void bytes(std::string_view bytes) override { parts.back().bytes.append(bytes); }
  void end() override {}
};

TEST(Multipart, AFormReadInPiecesOfAnySizeIsTheSameForm) {
  std::string mesh;
  std::mt19937 random(7);
  for (int i = 0; i < 5000; ++i) mesh += static_cast<char>(random() % 256);
  mesh += "\r\n--XY\r\n-XyZ\r\n--Xy";  // near-delimiters inside the file
  const std::string body =
      "preamble\r\n--XyZ\r\nContent-Disposition: form-data; name=\"options\"\r\n\r\n[]\r\n"
      "--XyZ\r\nContent-Disposition: form-data; name=\"file\"; filename=\"m.obj\"\r\n\r\n" +
      mesh + "\r\n--XyZ--\r\nepilogue";
  for (size_t piece : {size_t(1), size_t(2), size_t(3), size_t(7), size_t(64), size_t(4096), body.size()}) {
    Collected collected;
    MultipartReader reader("XyZ", collected);
    for (size_t at = 0; at < body.size(); at += piece) reader.feed(std::string_view(body).substr(at, piece));
    reader.finish();
    ASSERT_EQ(collected.parts.size(), 2u) << piece;
    EXPECT_EQ(collected.parts[0].bytes, "[]") << piece;
    EXPECT_EQ(collected.parts[1].fileName, "m.obj");
    EXPECT_EQ(collected.parts[1].bytes, mesh) << piece;
  }
  // Random pieces.
  for (int trial = 0; trial < 50; ++trial) {
    Collected collected;
    MultipartReader reader("XyZ", collected);
    for (size_t at = 0; at < body.size();) {
      const size_t piece = 1 + random() % 300;
      reader.feed(std::string_view(body).substr(at, piece));
      at += piece;
    }
    reader.finish();
    ASSERT_EQ(collected.parts.size(), 2u);
    EXPECT_EQ(collected.parts[1].bytes, mesh);
  }
}

TEST(Multipart, AFormWithoutEndOrWithTooManyOrTooLargePartsIsRefused) {
  Collected collected;
  MultipartReader unended("b", collected);
  unended.feed("--b\r\nContent-Disposition: form-data; name=\"a\"\r\n\r\nxx");
  EXPECT_THROW(unended.finish(), std::invalid_argument);
  std::string many;
  for (size_t i = 0; i <= MultipartReader::kMostParts; ++i) {
    many += "--b\r\nContent-Disposition: form-data; name=\"a\"\r\n\r\nx\r\n";
  }
  MultipartReader tooMany("b", collected);
  EXPECT_THROW(tooMany.feed(many), std::invalid_argument);
  MultipartReader longHeader("b", collected);
  EXPECT_THROW(longHeader.feed("--b\r\nX-A: " + std::string(MultipartReader::kLongestPartHeader + 10, 'a')),
               std::invalid_argument);
}

TEST(UploadForm, TheMeshGoesToItsFileAndTheFieldsAreChecked) {
  TempDir dir;
  Spool spool(dir.path() / "spool");
  const std::string mesh = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const std::string body =
      "--b\r\nContent-Disposition: form-data; name=\"file\"; filename=\"..\\\\evil\u202E\tname.obj\"\r\n\r\n" + mesh +
      "\r\n--b\r\nContent-Disposition: form-data; name=\"priority\"\r\n\r\n4\r\n--b--\r\n";
  UploadForm form(spool.begin(), "b");
  for (size_t at = 0; at < body.size(); at += 5) form.feed(std::string_view(body).substr(at, 5));
  const Submission submission = form.finish("root");
  EXPECT_EQ(submission.fileName, "evilname.obj");
  EXPECT_EQ(submission.priority, 4);
  ASSERT_TRUE(submission.upload);
  EXPECT_EQ(test::readFile(submission.upload->folder() / "evilname.obj"), mesh);

  const auto refusedWith = [&](const std::string& form) {
    UploadForm upload(spool.begin(), "b");
    return refusal([&] {
      upload.feed(form);
      (void)upload.finish("root");
    });
  };
  EXPECT_EQ(refusedWith("--b\r\nContent-Disposition: form-data; name=\"priority\"\r\n\r\n2147483648\r\n"
                        "--b\r\nContent-Disposition: form-data; name=\"file\"; filename=\"a.obj\"\r\n\r\nv\r\n--b--"),
            400);
  EXPECT_EQ(refusedWith("--b\r\nContent-Disposition: form-data; name=\"owner\"\r\n\r\nmallory\r\n--b--"), 400);
  EXPECT_EQ(refusedWith("--b\r\nContent-Disposition: form-data; name=\"file\"; filename=\"..\"\r\n\r\nv\r\n--b--"),
            400);
  EXPECT_EQ(refusedWith("--b\r\nContent-Disposition: form-data; name=\"options\"\r\n\r\n[]\r\n--b--"), 400);
  // Nothing of a refused upload stays in the spool: the accepted one's entry only.
  size_t entries = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(spool.folder())) ++entries;
  EXPECT_EQ(entries, 1u);
}

}  // namespace
}  // namespace rotafab::service
