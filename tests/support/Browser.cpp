#include "tests/support/Browser.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

namespace rotafab::testing {
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using nlohmann::json;
using namespace std::chrono_literals;

namespace {

// The names below carry a "browser" prefix: in a unity build this file shares
// a translation unit with others, whose private names must not collide.
using BrowserClock = std::chrono::steady_clock;

// How long chromium may take to start and show its page.
constexpr auto kBrowserStartLimit = 20s;
// How long the page may take to load after Page.navigate.
constexpr auto kBrowserLoadLimit = 30s;
// How long chromium may take to quit on SIGTERM before it is killed.
constexpr auto kBrowserQuitLimit = 5s;

// The chromium to run: $ROTAFAB_CHROMIUM, else Debian's binary itself rather
// than its /usr/bin/chromium wrapper script, whose default flags (extensions,
// GPU rasterization) and shell noise a test does not want, else the wrapper.
std::string browserExecutable() {
  if (const char* chosen = std::getenv("ROTAFAB_CHROMIUM"); chosen != nullptr && *chosen != '\0') {
    if (::access(chosen, X_OK) != 0)
      throw std::runtime_error(fmt::format("ROTAFAB_CHROMIUM={} is not a program", chosen));
    return chosen;
  }
  for (const char* candidate : {"/usr/lib/chromium/chromium", "/usr/bin/chromium", "/usr/bin/chromium-browser"}) {
    if (::access(candidate, X_OK) == 0) return candidate;
  }
  throw std::runtime_error("chromium is not installed (apt-get install chromium, or set ROTAFAB_CHROMIUM)");
}

// The last lines of chromium's log, to explain why it failed.
std::string browserLogTail(const fs::path& log, std::size_t count = 12) {
  std::ifstream in(log);
  std::deque<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    // Chromium complains of the missing D-Bus at every start: no clue there.
    if (line.empty() || line.find("ERROR:dbus/") != std::string::npos) continue;
    lines.push_back(std::move(line));
    if (lines.size() > count) lines.pop_front();
  }
  if (lines.empty()) return "\n(chromium wrote nothing)";
  std::string text = "\nchromium's last output:";
  for (const std::string& line : lines) text += "\n  " + line;
  return text;
}

// A JSON value as plain text: strings without their quotes.
std::string browserText(const json& value) { return value.is_string() ? value.get<std::string>() : value.dump(); }

// Only the first line: errors() promises one line per error, and a stack
// trace after the message would break that.
std::string browserFirstLine(std::string text) {
  if (const auto end = text.find('\n'); end != std::string::npos) text.resize(end);
  return text;
}

// How a page's JavaScript value reads in a console message.
std::string browserRemoteObjectText(const json& object) {
  if (object.contains("value")) return browserText(object["value"]);
  if (object.contains("unserializableValue")) return browserText(object["unserializableValue"]);  // NaN, 1n, ...
  if (object.contains("description")) return browserFirstLine(browserText(object["description"]));
  return object.value("type", "?");
}

// " (url:line:column)", 1-based as an editor shows it, or "" without a url.
std::string browserLocation(const json& where) {
  const std::string url = where.value("url", "");
  if (url.empty()) return "";
  return fmt::format(" ({}:{}:{})", url, where.value("lineNumber", 0) + 1, where.value("columnNumber", 0) + 1);
}

// http://host:port/favicon.ico (the query aside).
bool browserIsRootFavicon(std::string_view url) {
  url = url.substr(0, url.find_first_of("?#"));
  const auto scheme = url.find("://");
  if (scheme == std::string_view::npos) return false;
  const auto path = url.find('/', scheme + 3);
  return path != std::string_view::npos && url.substr(path) == "/favicon.ico";
}

// Runtime.ExceptionDetails as one line: "Uncaught Error: boom (url:3:9)".
std::string browserExceptionText(const json& details) {
  std::string text = details.value("text", "Uncaught");
  if (details.contains("exception")) {
    const std::string what = browserRemoteObjectText(details["exception"]);
    // Chromium sometimes repeats the message in "text" already.
    if (text.find(what) == std::string::npos) text += " " + what;
  }
  return browserFirstLine(text) + browserLocation(details);
}

// Page.captureScreenshot's image is base64; decode it without depending on a
// library's internals (Beast's decoder is in its detail namespace).
std::string browserBase64Decode(std::string_view text) {
  constexpr std::string_view kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bytes;
  bytes.reserve(text.size() / 4 * 3);
  unsigned bits = 0;
  int count = 0;
  for (const char c : text) {
    if (c == '=') break;
    const auto digit = kDigits.find(c);
    if (digit == std::string_view::npos) continue;  // CDP sends no line breaks, but a decoder may skip them
    bits = ((bits << 6) | static_cast<unsigned>(digit)) & 0xFFFFFFu;
    count += 6;
    if (count >= 8) {
      count -= 8;
      bytes.push_back(static_cast<char>((bits >> count) & 0xFFu));
    }
  }
  return bytes;
}

}  // namespace

struct Browser::Impl {
  fs::path folder;  // the temporary folder: profile and log
  pid_t pid = -1;   // chromium, leader of its own process group; -1 once reaped
  asio::io_context io;
  std::optional<websocket::stream<beast::tcp_stream>> ws;
  beast::flat_buffer incoming;
  beast::error_code lost;          // why the connection ended, once it has
  std::deque<std::string> outbox;  // commands not yet written, the first one being written
  bool writing = false;
  int lastId = 0;
  std::map<int, json> replies;  // replies no call has taken yet
  std::set<int> abandoned;      // commands whose caller gave up: their replies are dropped
  int loads = 0;                // Page.loadEventFired so far
  bool crashed = false;         // the page's renderer died; a navigation loads it anew
  std::vector<std::string> errors;

  Impl(int width, int height);
  ~Impl() { stop(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  fs::path logFile() const { return folder / "chromium.log"; }
  void launch(int width, int height);
  unsigned short waitForPort(BrowserClock::time_point deadline);
  std::string httpGet(unsigned short port, const std::string& target);
  void connect(unsigned short port, BrowserClock::time_point deadline);
  std::optional<std::string> exitState() const;
  std::string startFailure(const std::string& what) const;
  void read();
  void flush();
  void receive(const std::string& text);
  int send(const std::string& method, json params);
  template <class Done>
  bool pump(Done done, BrowserClock::time_point deadline, const std::string& doing);
  json call(const std::string& method, json params, std::chrono::milliseconds timeout);
  json evaluate(const std::string& expression, std::chrono::milliseconds timeout);
  void viewport(int width, int height, bool mobile, double scale);
  void stop() noexcept;
};

Browser::Impl::Impl(int width, int height) {
  std::string pattern = (fs::temp_directory_path() / "rotafab-browser-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error(fmt::format("cannot create a temporary folder {}: {}", pattern, std::strerror(errno)));
  }
  folder = pattern;
  // A constructor that throws gets no destructor: stop here what was started.
  try {
    const auto deadline = BrowserClock::now() + kBrowserStartLimit;
    launch(width, height);
    const unsigned short port = waitForPort(deadline);
    connect(port, deadline);
    // Inspector: to hear of a crashed page (Inspector.targetCrashed).
    for (const char* domain : {"Runtime", "Page", "Log", "Inspector"}) {
      call(std::string(domain) + ".enable", json::object(), 10s);
    }
    // Headless chromium keeps room for a toolbar it does not draw: a
    // 1280x900 window has a 1280x757 page. Tests mean the page's size.
    viewport(width, height, false, 1);
    // Until frames come at the display's rate, a page that measured its
    // frame rate would see 20 fps instead of 60: wait for five quick frames
    // in a row. That takes 0.1 s here; on a busy machine longer, but it never
    // fails the start (3 s at most).
    evaluate(R"(new Promise(resolve => {
      const giveUp = setTimeout(resolve, 3000);
      let last = 0, quick = 0;
      requestAnimationFrame(function frame(now) {
        quick = last > 0 && now - last < 40 ? quick + 1 : 0;
        last = now;
        if (quick < 5) return requestAnimationFrame(frame);
        clearTimeout(giveUp);
        resolve();
      });
    }))",
             10s);
  } catch (...) {
    stop();
    throw;
  }
}

void Browser::Impl::launch(int width, int height) {
  const std::string program = browserExecutable();
  std::vector<std::string> args = {
      program,
      "--headless=new",
      "--no-sandbox",  // root cannot use chromium's sandbox
      // Any free port, announced in the profile's DevToolsActivePort: tests
      // running in parallel do not collide.
      "--remote-debugging-port=0",
      "--user-data-dir=" + (folder / "profile").string(),
      fmt::format("--window-size={},{}", width, height),
      "--no-first-run",
      "--no-default-browser-check",
  };
  // WebGL on the CPU (SwiftShader), as there is no GPU. Chromium still falls
  // back to it by itself, but warns that the fallback is deprecated unless
  // the opt-in flag is given. With the GPU compositor, chromium draws no
  // frames for its first second or two; the software one (--disable-gpu)
  // starts at once, at 60 fps, and WebGL still works.
  args.insert(args.end(), {"--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu"});
  // Containers often have a 64 MB /dev/shm, which chromium fills and then crashes.
  args.emplace_back("--disable-dev-shm-usage");
  // No traffic of its own (updates, sync, field trials): tests run offline
  // and should not wait on it. No keyring to ask over D-Bus.
  args.insert(args.end(), {"--disable-background-networking", "--disable-component-update", "--disable-sync",
                           "--disable-extensions", "--disable-default-apps", "--password-store=basic", "--mute-audio"});
  // Timers and animation frames at full rate, whatever chromium thinks of the
  // window's visibility: a page measures its frame rate.
  args.insert(args.end(), {"--disable-background-timer-throttling", "--disable-backgrounding-occluded-windows",
                           "--disable-renderer-backgrounding"});
  args.emplace_back("about:blank");  // so that there is a page target to connect to
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);

  // Everything the child needs is prepared here: between fork and exec a
  // multi-threaded process may only make async-signal-safe calls.
  const int log = ::open(logFile().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int nothing = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  int execFailure[2] = {-1, -1};  // the child writes errno here if exec fails; exec closes it
  if (log < 0 || nothing < 0 || ::pipe2(execFailure, O_CLOEXEC) != 0) {
    const int error = errno;
    for (const int fd : {log, nothing, execFailure[0], execFailure[1]}) {
      if (fd >= 0) ::close(fd);
    }
    throw std::runtime_error(fmt::format("cannot prepare to start chromium: {}", std::strerror(error)));
  }
  const pid_t parent = ::getpid();
  const pid_t child = ::fork();
  if (child == 0) {
    // Its own process group, so that stopping it reaches its renderer and
    // GPU processes too; killed with the thread that started it, so that a
    // test that crashes leaves no chromium behind.
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);  // a mask the test blocked would survive exec
    ::dup2(nothing, STDIN_FILENO);
    ::dup2(log, STDOUT_FILENO);
    ::dup2(log, STDERR_FILENO);
    ::execv(argv[0], argv.data());
    const int error = errno;
    [[maybe_unused]] const auto written = ::write(execFailure[1], &error, sizeof error);
    ::_exit(127);
  }
  const int forkError = errno;
  ::close(log);
  ::close(nothing);
  ::close(execFailure[1]);
  if (child < 0) {
    ::close(execFailure[0]);
    throw std::runtime_error(fmt::format("cannot start chromium: fork: {}", std::strerror(forkError)));
  }
  pid = child;
  ::setpgid(child, child);  // also here, so that the group exists before the parent ever signals it
  int execError = 0;
  ssize_t got;
  do got = ::read(execFailure[0], &execError, sizeof execError);
  while (got < 0 && errno == EINTR);
  ::close(execFailure[0]);
  if (got == static_cast<ssize_t>(sizeof execError)) {
    throw std::runtime_error(fmt::format("cannot run {}: {}", program, std::strerror(execError)));
  }
}

// How chromium ended, or nothing while it runs. Leaves it unreaped, so that
// its process group id stays reserved for stop() to signal.
std::optional<std::string> Browser::Impl::exitState() const {
  if (pid <= 0) return "chromium has been stopped";
  siginfo_t info{};
  if (::waitid(P_PID, pid, &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid != pid) return std::nullopt;
  if (info.si_code == CLD_EXITED) return fmt::format("chromium exited with status {}", info.si_status);
  return fmt::format("chromium was killed by signal {} ({})", info.si_status, ::strsignal(info.si_status));
}

std::string Browser::Impl::startFailure(const std::string& what) const {
  const auto state = exitState();
  return fmt::format("chromium did not start: {}{}{}", what, state ? "; " + *state : "", browserLogTail(logFile()));
}

// Chromium writes the port it chose, then the browser's websocket path, to
// DevToolsActivePort in the profile.
unsigned short Browser::Impl::waitForPort(BrowserClock::time_point deadline) {
  const fs::path announced = folder / "profile" / "DevToolsActivePort";
  for (;;) {
    std::ifstream in(announced);
    unsigned port = 0;
    std::string path;
    // Both lines there: the file is complete, not caught half-written.
    if (in >> port >> path && port > 0 && port < 65536) return static_cast<unsigned short>(port);
    if (exitState()) throw std::runtime_error(startFailure("it quit before it listened for DevTools"));
    if (BrowserClock::now() >= deadline) {
      throw std::runtime_error(startFailure("no DevToolsActivePort within 20 s"));
    }
    std::this_thread::sleep_for(50ms);
  }
}

// Connects `stream` to chromium's DevTools port on loopback, then calls
// `next`; an error is left in `failure` instead.
template <typename Stream, typename Next>
void connectThen(Stream& stream, unsigned short port, beast::error_code& failure, Next next) {
  stream.async_connect(asio::ip::tcp::endpoint(asio::ip::address_v4::loopback(), port),
                       [&failure, next = std::move(next)](beast::error_code ec) mutable {
                         if (ec) {
                           failure = ec;
                           return;
                         }
                         next();
                       });
}

// The body of a GET from chromium's DevTools HTTP server; throws if there is
// no answer within 5 s.
std::string Browser::Impl::httpGet(unsigned short port, const std::string& target) {
  beast::tcp_stream stream(io);
  http::request<http::empty_body> request(http::verb::get, target, 11);
  request.set(http::field::host, fmt::format("127.0.0.1:{}", port));
  beast::flat_buffer buffer;
  http::response<http::string_body> response;
  beast::error_code failure;
  // The stream's expiry bounds connect, write and read together: when it
  // passes, the socket closes and the pending step completes with a timeout.
  stream.expires_after(5s);
  connectThen(stream, port, failure, [&] {
    http::async_write(stream, request, [&](beast::error_code ec, std::size_t) {
      if (ec) {
        failure = ec;
        return;
      }
      http::async_read(stream, buffer, response, [&](beast::error_code ec, std::size_t) { failure = ec; });
    });
  });
  io.restart();
  io.run();
  if (failure) throw std::runtime_error(startFailure(fmt::format("GET {}: {}", target, failure.message())));
  return response.body();
}

// Finds the page chromium opened and connects to its websocket.
void Browser::Impl::connect(unsigned short port, BrowserClock::time_point deadline) {
  std::string page;
  for (;;) {
    const json targets = json::parse(httpGet(port, "/json/list"), nullptr, false);
    if (targets.is_array()) {
      for (const json& target : targets) {
        if (target.value("type", "") == "page" && target.contains("id")) {
          page = browserText(target["id"]);
          break;
        }
      }
    }
    if (!page.empty()) break;
    if (exitState()) throw std::runtime_error(startFailure("it quit before it opened a page"));
    if (BrowserClock::now() >= deadline) throw std::runtime_error(startFailure("no page target within 20 s"));
    std::this_thread::sleep_for(50ms);
  }

  ws.emplace(io);
  auto& stream = beast::get_lowest_layer(*ws);
  beast::error_code failure;
  stream.expires_after(5s);
  connectThen(stream, port, failure, [&] {
    ws->async_handshake(fmt::format("127.0.0.1:{}", port), "/devtools/page/" + page,
                        [&](beast::error_code ec) { failure = ec; });
  });
  io.restart();
  io.run();
  if (failure) throw std::runtime_error(startFailure(fmt::format("websocket to page {}: {}", page, failure.message())));
  // From now on each wait has its own deadline (pump); an expiry on the
  // stream would close the connection for good at the first slow reply.
  stream.expires_never();
  ws->text(true);
  ws->read_message_max(512u << 20);  // a full-page screenshot in base64 can pass Beast's default 16 MB
  read();
}

// Keeps one read pending at all times; every message goes to receive().
void Browser::Impl::read() {
  ws->async_read(incoming, [this](beast::error_code ec, std::size_t) {
    if (ec) {
      lost = ec;
      return;
    }
    const std::string text = beast::buffers_to_string(incoming.data());
    incoming.consume(incoming.size());
    receive(text);
    read();
  });
}

// Writes the outbox in order, one message at a time, as Beast requires.
void Browser::Impl::flush() {
  if (writing || outbox.empty() || lost) return;
  writing = true;
  ws->async_write(asio::buffer(outbox.front()), [this](beast::error_code ec, std::size_t) {
    writing = false;
    if (ec) {
      lost = ec;
      return;
    }
    outbox.pop_front();
    flush();
  });
}

int Browser::Impl::send(const std::string& method, json params) {
  const int id = ++lastId;
  outbox.push_back(json{{"id", id}, {"method", method}, {"params", std::move(params)}}.dump());
  flush();
  return id;
}

// A reply is kept for its caller; of the events, only what the API reports.
void Browser::Impl::receive(const std::string& text) {
  try {
    json message = json::parse(text);
    if (message.contains("id")) {
      const int id = message["id"].get<int>();
      if (abandoned.erase(id) == 0) replies[id] = std::move(message);
      return;
    }
    const std::string method = message.value("method", "");
    const json params = message.value("params", json::object());
    if (method == "Page.loadEventFired") {
      ++loads;
    } else if (method == "Inspector.targetCrashed") {
      crashed = true;
      errors.push_back("the page crashed (its renderer died)");
    } else if (method == "Runtime.exceptionThrown") {
      errors.push_back(browserExceptionText(params.value("exceptionDetails", json::object())));
    } else if (method == "Runtime.consoleAPICalled") {
      const std::string type = params.value("type", "");
      if (type != "error" && type != "assert") return;
      std::string line = "console." + type + ":";
      for (const json& arg : params.value("args", json::array())) line += " " + browserRemoteObjectText(arg);
      const json frames = params.value("stackTrace", json::object()).value("callFrames", json::array());
      if (!frames.empty()) line += browserLocation(frames[0]);
      errors.push_back(browserFirstLine(line));
    } else if (method == "Log.entryAdded") {
      const json entry = params.value("entry", json::object());
      if (entry.value("level", "") != "error") return;
      const std::string url = entry.value("url", "");
      // Chromium asks every server for /favicon.ico by itself, whether or not
      // the page names one, and its 404 arrives at any time after the load.
      if (browserIsRootFavicon(url)) return;
      errors.push_back(browserFirstLine(entry.value("text", "?")) + (url.empty() ? "" : " (" + url + ")"));
    } else if (method == "Page.javascriptDialogOpening") {
      // A dialog stops the page's scripts until someone answers it.
      abandoned.insert(send("Page.handleJavaScriptDialog", {{"accept", true}}));
    }
  } catch (const json::exception&) {
    // Not CDP as this file knows it: nothing a test waits for.
  }
}

// Runs the socket's handlers until done() or the deadline: false at the
// deadline. Throws if the connection is gone, as nothing can come then.
template <class Done>
bool Browser::Impl::pump(Done done, BrowserClock::time_point deadline, const std::string& doing) {
  while (!done()) {
    if (lost) {
      // The socket closes as chromium dies, a moment before it shows as exited.
      auto state = exitState();
      for (int wait = 0; !state && wait < 25; ++wait) {
        std::this_thread::sleep_for(20ms);
        state = exitState();
      }
      throw std::runtime_error(fmt::format("{}: the connection to chromium was lost ({}){}", doing, lost.message(),
                                           state ? "; " + *state + browserLogTail(logFile()) : ""));
    }
    if (BrowserClock::now() >= deadline) return false;
    if (io.stopped()) io.restart();
    io.run_one_until(deadline);
  }
  return true;
}

json Browser::Impl::call(const std::string& method, json params, std::chrono::milliseconds timeout) {
  if (params.is_null()) params = json::object();  // CDP wants an object, even an empty one
  // A crashed page answers nothing but a new navigation: fail now rather
  // than at the timeout.
  const bool reloads = method == "Page.navigate" || method == "Page.reload";
  if (crashed && !reloads) throw std::runtime_error(fmt::format("{}: the page has crashed; navigate again", method));
  if (reloads) crashed = false;
  const int id = send(method, std::move(params));
  if (!pump([&] { return replies.count(id) > 0 || crashed; }, BrowserClock::now() + timeout, method)) {
    abandoned.insert(id);
    throw std::runtime_error(fmt::format("{}: no reply within {} ms", method, timeout.count()));
  }
  if (replies.count(id) == 0) {
    abandoned.insert(id);
    throw std::runtime_error(fmt::format("{}: the page crashed", method));
  }
  const json reply = std::move(replies[id]);
  replies.erase(id);
  if (reply.contains("error")) {
    const json& error = reply["error"];
    std::string text = error.contains("message") ? browserText(error["message"]) : error.dump();
    if (error.contains("data")) text += " (" + browserText(error["data"]) + ")";
    throw std::runtime_error(fmt::format("{} failed: {}", method, text));
  }
  return reply.value("result", json::object());
}

json Browser::Impl::evaluate(const std::string& expression, std::chrono::milliseconds timeout) {
  const json result = call("Runtime.evaluate",
                           {{"expression", expression},
                            {"returnByValue", true},
                            {"awaitPromise", true},
                            // As if the user acted: click() may then open what only a user may.
                            {"userGesture", true}},
                           timeout);
  if (result.contains("exceptionDetails")) {
    std::string shown = browserFirstLine(expression);
    if (shown.size() > 80 || shown.size() < expression.size()) shown = shown.substr(0, 77) + "...";
    throw std::runtime_error(fmt::format("evaluate `{}`: {}", shown, browserExceptionText(result["exceptionDetails"])));
  }
  const json value = result.value("result", json::object());
  if (value.contains("value")) return value["value"];
  if (value.contains("unserializableValue")) return value["unserializableValue"];  // "NaN", "Infinity", "1n"
  return nullptr;  // undefined, or what JSON cannot hold
}

void Browser::Impl::viewport(int width, int height, bool mobile, double scale) {
  call("Emulation.setDeviceMetricsOverride",
       {{"width", width}, {"height", height}, {"deviceScaleFactor", scale}, {"mobile", mobile}}, 30s);
  // A phone or tablet has a touch screen, and pages ask for one ("ontouchstart", pointer: coarse).
  call("Emulation.setTouchEmulationEnabled", {{"enabled", mobile}, {"maxTouchPoints", mobile ? 5 : 1}}, 30s);
}

void Browser::Impl::stop() noexcept {
  if (ws) {
    // No websocket close handshake: it would wait on chromium, which is about to go anyway.
    beast::error_code ignored;
    beast::get_lowest_layer(*ws).socket().close(ignored);
    // Completes the pending read and write (as aborted) while their objects still live.
    try {
      io.restart();
      io.poll();
    } catch (...) {
    }
  }
  if (pid > 0) {
    ::kill(pid, SIGTERM);  // lets chromium close its profile and its children
    const auto deadline = BrowserClock::now() + kBrowserQuitLimit;
    while (!exitState() && BrowserClock::now() < deadline) std::this_thread::sleep_for(20ms);
    // Not reaped yet, so the group id is still chromium's: this reaches any
    // child left behind, and chromium itself if it ignored SIGTERM.
    ::kill(-pid, SIGKILL);
    int status;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    pid = -1;
  }
  if (!folder.empty()) {
    // A child that was just killed may still have had a file open a moment
    // ago; a second try covers files it created meanwhile.
    for (int attempt = 0; attempt < 5; ++attempt) {
      std::error_code ec;
      fs::remove_all(folder, ec);
      if (!ec && !fs::exists(folder, ec)) break;
      std::this_thread::sleep_for(100ms);
    }
  }
}

Browser::Browser(int width, int height) : impl_(std::make_unique<Impl>(width, height)) {}

Browser::~Browser() = default;

json Browser::call(const std::string& method, json params, std::chrono::milliseconds timeout) {
  return impl_->call(method, std::move(params), timeout);
}

void Browser::navigate(const std::string& url) {
  const int before = impl_->loads;
  const json result = impl_->call("Page.navigate", {{"url", url}}, kBrowserLoadLimit);
  if (const std::string error = result.value("errorText", ""); !error.empty()) {
    throw std::runtime_error(fmt::format("navigate to {}: {}", url, error));
  }
  // A navigation within the document (only the #fragment changes) has no
  // loader and no load event to wait for.
  if (!result.contains("loaderId")) return;
  if (!impl_->pump([&] { return impl_->loads > before || impl_->crashed; }, BrowserClock::now() + kBrowserLoadLimit,
                   "navigate to " + url)) {
    throw std::runtime_error(fmt::format("navigate to {}: no load event within 30 s", url));
  }
  if (impl_->crashed) throw std::runtime_error(fmt::format("navigate to {}: the page crashed", url));
}

json Browser::evaluate(const std::string& expression, std::chrono::milliseconds timeout) {
  return impl_->evaluate(expression, timeout);
}

bool Browser::waitFor(const std::string& condition, std::chrono::milliseconds timeout) {
  const auto deadline = BrowserClock::now() + timeout;
  // On lines of its own, so that a condition ending in a // comment still works.
  const std::string expression = "!!(\n" + condition + "\n)";
  for (;;) {
    // A page stuck in a loop does not answer; the wait still ends near its deadline.
    const auto remaining = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - BrowserClock::now());
    try {
      if (impl_->evaluate(expression, std::max(remaining, std::chrono::milliseconds(200))) == true) return true;
    } catch (const std::runtime_error&) {
      // Not yet defined, or the page is between documents: not true yet. A
      // crash is for the test to hear of, as is a lost connection (from pump).
      if (impl_->crashed) throw;
    }
    const auto now = BrowserClock::now();
    if (now >= deadline) return false;
    impl_->pump([] { return false; }, std::min(now + 100ms, deadline), "waitFor " + condition);
  }
}

void Browser::screenshot(const fs::path& png) {
  const json result = impl_->call("Page.captureScreenshot", {{"format", "png"}}, 30s);
  const std::string bytes = browserBase64Decode(result.at("data").get<std::string>());
  if (png.has_parent_path()) fs::create_directories(png.parent_path());
  std::ofstream out(png, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error(fmt::format("screenshot: cannot write {}", png.string()));
}

void Browser::setFiles(const std::string& cssSelector, const std::vector<fs::path>& files) {
  json paths = json::array();
  for (const fs::path& file : files) {
    // Chromium takes any path without a word and then fails the page's read.
    if (!fs::is_regular_file(file)) throw std::runtime_error(fmt::format("setFiles: no file {}", file.string()));
    paths.push_back(fs::absolute(file).string());
  }
  const json document = impl_->call("DOM.getDocument", {{"depth", 0}}, 30s);
  const json found =
      impl_->call("DOM.querySelector", {{"nodeId", document.at("root").at("nodeId")}, {"selector", cssSelector}}, 30s);
  if (found.value("nodeId", 0) == 0) throw std::runtime_error(fmt::format("setFiles: nothing matches {}", cssSelector));
  impl_->call("DOM.setFileInputFiles", {{"files", paths}, {"nodeId", found["nodeId"]}}, 30s);
}

void Browser::setViewport(int width, int height, bool mobile, double scale) {
  impl_->viewport(width, height, mobile, scale);
}

std::vector<std::string> Browser::errors() const { return impl_->errors; }

fs::path Browser::logFile() const { return impl_->logFile(); }

}  // namespace rotafab::testing
