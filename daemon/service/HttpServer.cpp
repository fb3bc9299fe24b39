#include "daemon/service/HttpServer.h"

#include <fmt/format.h>
#include <openssl/rand.h>
#include <pwd.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <charconv>
#include <chrono>
#include <deque>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <unordered_map>
#include <utility>

#include "core/ProgramFolders.h"
#include "daemon/service/Multipart.h"

namespace rotafab::service {
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Who is asking, as the connection shows it.
struct Identity {
  bool allowed = false;
  std::string name;  // the owner of what they submit
  std::string refusal;
  bool bySession = false;  // a browser's session: it may not ask for login links
};

using Clock = std::chrono::steady_clock;

// A login link works once, within this time; a session lasts this long unused.
constexpr auto kLoginLinkLasts = std::chrono::minutes(5);
constexpr auto kSessionLasts = std::chrono::hours(24 * 7);

// 32 random bytes from OpenSSL's generator, as hex: a login code or a session.
std::string randomSecret() {
  unsigned char bytes[32];
  if (RAND_bytes(bytes, sizeof bytes) != 1) throw ApiError(500, "no random bytes for a secret");
  std::string text;
  for (unsigned char byte : bytes) text += fmt::format("{:02x}", byte);
  return text;
}

// The page's files (HTML, CSS, JavaScript): PREFIX/share/rotafab/web once
// installed; the source tree's daemon/web for a program run from its build tree.
fs::path pageFolder() {
  const fs::path installed = core::installedDataFolder() / "web";
  std::error_code error;
  if (fs::is_directory(installed, error)) return installed;
#if defined(ROTAFAB_WEB_DIR) && defined(ROTAFAB_BUILD_DIR)
  if (fs::equivalent(core::programFolder(), ROTAFAB_BUILD_DIR, error)) return ROTAFAB_WEB_DIR;
#endif
  return "/usr/share/rotafab/web";
}

// Debian's libjs-three, which the page's 3D view loads: only the files it uses.
constexpr std::string_view kThreeFolder = "/usr/share/javascript/three";
const std::set<std::string>& threeFiles() {
  static const std::set<std::string> files{"build/three.min.js", "examples/js/controls/OrbitControls.js"};
  return files;
}

std::string contentTypeOf(const fs::path& file) {
  const std::string extension = file.extension().string();
  if (extension == ".html") return "text/html; charset=utf-8";
  if (extension == ".js") return "text/javascript; charset=utf-8";
  if (extension == ".css") return "text/css; charset=utf-8";
  if (extension == ".svg") return "image/svg+xml";
  if (extension == ".png") return "image/png";
  if (extension == ".json") return "application/json";
  return "text/plain; charset=utf-8";
}

std::optional<std::string> accountName(uid_t uid) {
  struct passwd entry {};
  struct passwd* found = nullptr;
  char buffer[4096];
  if (::getpwuid_r(uid, &entry, buffer, sizeof buffer, &found) == 0 && found) return std::string(found->pw_name);
  return std::nullopt;
}

std::optional<long long> wholeNumber(std::string_view text) {
  long long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

// The path split at '/': "/api/jobs/7/start" -> api, jobs, 7, start; the query dropped.
std::vector<std::string> pathParts(std::string_view target, std::string& query) {
  const size_t mark = target.find('?');
  query = mark == std::string_view::npos ? "" : std::string(target.substr(mark + 1));
  target = target.substr(0, mark);
  std::vector<std::string> parts;
  while (!target.empty()) {
    const size_t slash = target.find('/');
    if (slash != 0) parts.emplace_back(target.substr(0, slash));
    if (slash == std::string_view::npos) break;
    target = target.substr(slash + 1);
  }
  return parts;
}

std::string queryValue(const std::string& query, std::string_view key) {
  std::string_view rest = query;
  while (!rest.empty()) {
    const size_t amp = rest.find('&');
    const std::string_view pair = rest.substr(0, amp);
    if (pair.starts_with(key) && pair.size() > key.size() && pair[key.size()] == '=') {
      return std::string(pair.substr(key.size() + 1));
    }
    if (amp == std::string_view::npos) break;
    rest = rest.substr(amp + 1);
  }
  return "";
}

// The `make` options of a submission: a JSON array of command-line words,
// or an object of option names and values ({"structure": "band", "score-folds": true}).
std::vector<std::string> optionWords(const json& options) {
  std::vector<std::string> words;
  if (options.is_null()) return words;
  if (options.is_array()) {
    for (const json& word : options) {
      if (!word.is_string())
        throw ApiError(400, "options: expected a list of words such as [\"--structure\", \"band\"]");
      words.push_back(word.get<std::string>());
    }
    return words;
  }
  if (!options.is_object()) throw ApiError(400, "options: expected a list of words or an object of options");
  for (const auto& [key, value] : options.items()) {
    const std::string flag = key.starts_with("--") ? key : "--" + key;
    if (value.is_boolean()) {
      if (value.get<bool>()) words.push_back(flag);
    } else if (value.is_string()) {
      words.push_back(flag), words.push_back(value.get<std::string>());
    } else if (value.is_number()) {
      words.push_back(flag), words.push_back(value.dump());
    } else {
      throw ApiError(400, fmt::format("options.{}: expected text, a number or true", key));
    }
  }
  return words;
}

int priorityOf(const json& value) {
  if (value.is_null()) return 0;
  if (value.is_number_integer()) return value.get<int>();
  if (value.is_string()) {
    if (auto number = wholeNumber(value.get<std::string>()); number && *number > -1000000 && *number < 1000000) {
      return static_cast<int>(*number);
    }
  }
  throw ApiError(400, "priority: expected a whole number");
}

}  // namespace

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  Impl(asio::io_context& io, Service& service, std::shared_ptr<spdlog::logger> log, HttpLimits limits)
      : io(io), service(service), log(std::move(log)), limits(limits) {}

  asio::io_context& io;
  Service& service;
  std::shared_ptr<spdlog::logger> log;
  HttpLimits limits;
  std::vector<std::unique_ptr<asio::local::stream_protocol::acceptor>> unixAcceptors;
  std::vector<std::unique_ptr<asio::ip::tcp::acceptor>> tcpAcceptors;
  std::vector<fs::path> socketFiles;
  std::vector<std::string> bound;
  size_t connections = 0;
  bool closing = false;
  // Every connection, to close them all at shutdown.
  struct Connection {
    virtual ~Connection() = default;
    virtual void close() = 0;
  };
  std::vector<std::weak_ptr<Connection>> open;

  // The names of the users who connected lately, on the I/O thread: a
  // lookup reads /etc/passwd through NSS, on every connection. A minute
  // old at most, so that a renamed account is seen under its new name.
  static constexpr auto kNameKeptFor = std::chrono::seconds(60);
  std::unordered_map<uid_t, std::pair<std::string, std::chrono::steady_clock::time_point>> names;

  Identity identify(asio::local::stream_protocol::socket& socket) {
    struct ucred credentials {};
    socklen_t size = sizeof credentials;
    if (::getsockopt(socket.native_handle(), SOL_SOCKET, SO_PEERCRED, &credentials, &size) != 0) {
      return {false, "", "the peer's credentials cannot be read"};
    }
    const auto now = std::chrono::steady_clock::now();
    auto known = names.find(credentials.uid);
    if (known == names.end() || now - known->second.second > kNameKeptFor) {
      const auto found = accountName(credentials.uid);
      // Not found, perhaps only for now: not kept, asked again next time.
      if (!found) return {true, fmt::format("uid {}", credentials.uid), ""};
      known = names.insert_or_assign(credentials.uid, std::pair{*found, now}).first;
    }
    return {true, known->second.first, ""};
  }

  // Over TCP nobody gets in without a token of the configuration or the
  // secret of a browser's session, which a one-time login link gave the page
  // (it keeps it in its origin's storage, which no other port's page reads,
  // and sends it as a bearer token; the event stream, which cannot send a
  // header, as `?session=`). No cookie: nothing a browser sends by itself.
  template <typename Request>
  Identity identify(asio::ip::tcp::socket&, const Request& request) {
    const auto& tokens = service.config().tokens;
    const auto header = request[http::field::authorization];
    const std::string_view value(header.data(), header.size());
    std::string secret;
    if (value.starts_with("Bearer ")) {
      secret = std::string(value.substr(7));
    } else {
      const std::string_view target(request.target().data(), request.target().size());
      if (target.starts_with("/api/events")) {
        std::string query;
        pathParts(target, query);
        secret = queryValue(query, "session");
      }
    }
    if (secret.empty()) {
      return {false, "",
              tokens.empty() ? "this listener needs a session: run `rotafab dashboard` on the daemon's machine for a "
                               "login link"
                             : "this listener needs a token: send `Authorization: Bearer TOKEN` (rotafab --token T), "
                               "or a session from `rotafab dashboard`"};
    }
    const auto now = Clock::now();
    if (const auto found = sessions.find(secret); found != sessions.end()) {
      if (now - found->second.second < kSessionLasts) {
        found->second.second = now;
        return {true, found->second.first, "", true};
      }
      sessions.erase(found);
    }
    for (const TokenConfig& configured : tokens) {
      if (tokenMatches(secret, configured.hash)) return {true, configured.name, "", false};
    }
    return {false, "",
            "the token or session is not one this daemon knows (a session ends when the daemon starts again): run "
            "`rotafab dashboard` for a new link"};
  }

  // One-time login links (code -> who, until when) and the sessions they
  // opened (secret -> who, last used); in memory: a daemon started again
  // asks everyone to sign in again.
  std::unordered_map<std::string, std::pair<std::string, Clock::time_point>> loginCodes;
  std::unordered_map<std::string, std::pair<std::string, Clock::time_point>> sessions;
  fs::path pages = pageFolder();

  std::string newLoginCode(const std::string& name) {
    const auto now = Clock::now();
    std::erase_if(loginCodes, [&](const auto& entry) { return entry.second.second < now; });
    std::string code = randomSecret();
    loginCodes[code] = {name, now + kLoginLinkLasts};
    return code;
  }

  // The secret of a new session for the code's holder; none when the code is unknown, used or old.
  std::optional<std::string> openSession(const std::string& code) {
    const auto found = loginCodes.find(code);
    if (found == loginCodes.end()) return std::nullopt;
    const auto [name, until] = found->second;
    loginCodes.erase(found);
    const auto now = Clock::now();
    if (until < now) return std::nullopt;
    std::erase_if(sessions, [&](const auto& entry) { return now - entry.second.second >= kSessionLasts; });
    std::string secret = randomSecret();
    sessions[secret] = {name, now};
    return secret;
  }

  // Where a browser on this machine reaches the daemon: its first loopback TCP listener.
  std::optional<std::string> loopbackPage() const {
    for (const std::string& address : bound) {
      if (address.starts_with("tcp://127.") || address.starts_with("tcp://[::1]")) {
        return "http://" + address.substr(6);
      }
    }
    return std::nullopt;
  }
};

namespace {

template <typename Protocol>
class Session : public HttpServer::Impl::Connection, public std::enable_shared_from_this<Session<Protocol>> {
 public:
  using Stream = beast::basic_stream<Protocol>;
  Session(typename Protocol::socket socket, std::shared_ptr<HttpServer::Impl> server)
      : stream_(std::move(socket)), server_(std::move(server)) {}

  void start(bool overLimit) {
    ++server_->connections;
    if constexpr (std::is_same_v<Protocol, asio::local::stream_protocol>) {
      identity_ = server_->identify(stream_.socket());
    }
    if (overLimit) {
      overLimit_ = true;
    }
    readHeader(true);
  }

  ~Session() override { --server_->connections; }

  void close() override {
    beast::error_code ignored;
    stream_.socket().shutdown(Protocol::socket::shutdown_both, ignored);
    stream_.socket().close(ignored);
  }

 private:
  void readHeader(bool first) {
    header_.emplace();
    header_->header_limit(static_cast<std::uint32_t>(server_->limits.headerBytes));
    header_->body_limit(server_->service.config().uploadLimit);
    stream_.expires_after(first ? server_->limits.header : server_->limits.idle);
    http::async_read_header(
        stream_, buffer_, *header_,
        [self = this->shared_from_this(), first](beast::error_code error, size_t) { self->onHeader(error, first); });
  }

  void onHeader(beast::error_code error, bool first) {
    if (error == http::error::end_of_stream || error == beast::error::timeout ||
        error == asio::error::operation_aborted || error == asio::error::connection_reset ||
        error == asio::error::eof) {
      if (error == beast::error::timeout && first)
        server_->log->info("a client sent no request within its time; closed");
      return close();
    }
    if (error == http::error::header_limit) {
      return fail(431, fmt::format("the request's header is larger than {} bytes", server_->limits.headerBytes));
    }
    if (error == http::error::body_limit) {  // the Content-Length said so before any of the body came
      return fail(413, fmt::format("the body is larger than the {} bytes the daemon takes",
                                   server_->service.config().uploadLimit));
    }
    if (error) return fail(400, fmt::format("malformed request: {}", error.message()));
    auto& request = header_->get();
    if (overLimit_) {
      return fail(503, fmt::format("the daemon serves {} connections at once; try again shortly",
                                   server_->service.config().connectionLimit));
    }
    if constexpr (std::is_same_v<Protocol, asio::ip::tcp>) identity_ = server_->identify(stream_.socket(), request);
    // The page's own files are the same for everyone and hold nothing of
    // the queue: served to anyone who reaches the listener; the API is not.
    const std::string_view path(request.target().data(), request.target().size());
    const bool page = !path.starts_with("/api");
    if (!identity_.allowed && !page) return fail(401, identity_.refusal);
    if (request.has_content_length() && *header_->content_length() > server_->service.config().uploadLimit) {
      return fail(413, fmt::format("the body is {} bytes; the daemon takes at most {}", *header_->content_length(),
                                   server_->service.config().uploadLimit));
    }
    const std::string target(request.target());
    if (request.method() == http::verb::get && target.starts_with("/api/events")) return startEvents(target);
    body_.emplace(std::move(*header_));
    body_->body_limit(server_->service.config().uploadLimit);
    stream_.expires_after(server_->limits.body);
    const auto expect = body_->get()[http::field::expect];
    if (beast::iequals(expect, "100-continue")) {
      auto continued = std::make_shared<std::string>("HTTP/1.1 100 Continue\r\n\r\n");
      asio::async_write(stream_, asio::buffer(*continued),
                        [self = this->shared_from_this(), continued](beast::error_code written, size_t) {
                          if (written) return self->close();
                          self->readBody();
                        });
      return;
    }
    readBody();
  }

  void readBody() {
    http::async_read(stream_, buffer_, *body_,
                     [self = this->shared_from_this()](beast::error_code error, size_t) { self->onBody(error); });
  }

  void onBody(beast::error_code error) {
    if (error == http::error::body_limit) {
      return fail(413, fmt::format("the body is larger than the {} bytes the daemon takes",
                                   server_->service.config().uploadLimit));
    }
    if (error == beast::error::timeout) {
      server_->log->info("a client did not send its request's body in time; closed");
      return fail(408, "the request's body did not come in time");
    }
    if (error) return close();
    stream_.expires_never();
    request_ = body_->release();
    try {
      route();
    } catch (const ApiError& refused) {
      respond({refused.status, {{"error", refused.what()}}});
    } catch (const std::exception& failure) {
      respond({400, {{"error", failure.what()}}});
    }
  }

  // The reply reaches the session on its own executor, whichever thread the service answered on.
  ReplyHandler replier() {
    return [self = this->shared_from_this()](Reply reply) {
      asio::post(self->stream_.get_executor(),
                 [self, reply = std::move(reply)]() mutable { self->respond(std::move(reply)); });
    };
  }

  json bodyJson() const {
    if (request_.body().empty()) return json::object();
    json body = json::parse(request_.body(), nullptr, false);
    if (body.is_discarded()) throw ApiError(400, "the body is not valid JSON");
    if (!body.is_object()) throw ApiError(400, "the body must be a JSON object");
    return body;
  }

  void route() {
    std::string query;
    const auto parts = pathParts(std::string_view(request_.target().data(), request_.target().size()), query);
    const http::verb method = request_.method();
    const auto wrongMethod = [&](const char* allowed) {
      throw ApiError(405, fmt::format("{} takes {}", std::string(request_.target()), allowed));
    };
    if (parts.empty() || parts[0] != "api") return page(parts, query);
    if (parts.size() == 1) {
      if (method != http::verb::get) wrongMethod("GET");
      return respond({200, {{"name", "rotafabd"}, {"version", "0.1.0"}, {"host", server_->service.config().host}}});
    }
    if (parts[1] == "sessions" && parts.size() == 2) {
      if (method != http::verb::post) wrongMethod("POST");
      return loginLink();
    }
    if (parts[1] == "devices" && parts.size() == 2) {
      if (method != http::verb::get) wrongMethod("GET");
      return server_->service.devices(replier());
    }
    if (parts[1] != "jobs") throw ApiError(404, fmt::format("no such resource: {}", std::string(request_.target())));
    if (parts.size() == 2) {
      if (method == http::verb::get) return server_->service.list(replier());
      if (method != http::verb::post) wrongMethod("GET and POST");
      return server_->service.submit(submission(), replier());
    }
    const auto id = wholeNumber(parts[2]);
    if (!id || *id <= 0) throw ApiError(404, fmt::format("no such job: {}", parts[2]));
    if (parts.size() == 3) {
      if (method != http::verb::get) wrongMethod("GET");
      return server_->service.status(*id, replier());
    }
    if (parts.size() == 4 && parts[3] == "manifest") {
      if (method != http::verb::get) wrongMethod("GET");
      return server_->service.manifest(*id, replier());
    }
    if (parts.size() == 5 && parts[3] == "files") {
      if (method != http::verb::get) wrongMethod("GET");
      return server_->service.file(*id, parts[4], replier());
    }
    if (parts.size() == 5 && parts[3] == "sheets") {
      if (method != http::verb::get) wrongMethod("GET");
      const auto sheet = wholeNumber(parts[4]);
      if (!sheet || *sheet < 1 || *sheet > 1000000) throw ApiError(404, fmt::format("no sheet {}", parts[4]));
      return server_->service.sheet(*id, static_cast<int>(*sheet), replier());
    }
    if (parts.size() == 4) {
      static const std::set<std::string> actions{"cancel", "pause", "resume", "start", "next", "move"};
      if (!actions.contains(parts[3])) {
        throw ApiError(404, fmt::format("no action {} (cancel, pause, resume, start, next, move)", parts[3]));
      }
      if (method != http::verb::post) wrongMethod("POST");
      return server_->service.act(*id, parts[3], bodyJson(), identity_.name, replier());
    }
    throw ApiError(404, fmt::format("no such resource: {}", std::string(request_.target())));
  }

  // The workshop page: its files, Debian's three.js, and the login link's landing.
  void page(const std::vector<std::string>& parts, const std::string& query) {
    if (request_.method() != http::verb::get) {
      throw ApiError(405, fmt::format("{} takes GET", std::string(request_.target())));
    }
    const auto notFound = [&] {
      return ApiError(404, fmt::format("no such page: {} (the page is at /, the API under /api; see docs/API.md)",
                                       std::string(request_.target())));
    };
    if (parts.size() == 1 && parts[0] == "login") {
      // The secret goes to the page in the fragment, which the browser
      // never sends to a server; the page keeps it and clears the address.
      const auto secret = server_->openSession(queryValue(query, "code"));
      Reply landing{303, nullptr};
      landing.text = "to the workshop page\n";
      landing.contentType = "text/plain; charset=utf-8";
      landing.headers = {{"Location", secret ? "/#session=" + *secret : "/#signin=used"}};
      return respond(std::move(landing));
    }
    if (parts.size() == 1 && parts[0] == "favicon.ico") {
      Reply none{204, nullptr};  // no icon: asked for by every browser of its own accord
      none.contentType = "image/x-icon";
      return respond(std::move(none));
    }
    Reply file;
    if (parts.empty()) {
      file.file = server_->pages / "index.html";
    } else if (parts.size() == 2 && parts[0] == "app") {
      static const std::regex kPageFile(R"([A-Za-z0-9_-]+\.(html|js|css|svg|png))");
      if (!std::regex_match(parts[1], kPageFile)) throw notFound();
      file.file = server_->pages / parts[1];
    } else if (parts.size() > 2 && parts[0] == "lib" && parts[1] == "three") {
      std::string rest;
      for (size_t i = 2; i < parts.size(); ++i) rest += (i > 2 ? "/" : "") + parts[i];
      if (!threeFiles().contains(rest)) throw notFound();
      file.file = fs::path(kThreeFolder) / rest;
    } else {
      throw notFound();
    }
    std::error_code error;
    if (!fs::is_regular_file(file.file, error)) {
      throw ApiError(404, fmt::format("{} is not installed (the page's files; see the README)", file.file.string()));
    }
    respond(std::move(file));
  }

  // A one-time link that opens a browser's session for who asks (over the
  // Unix socket: this machine's user; over TCP: the token's holder).
  void loginLink() {
    std::string base;
    if constexpr (std::is_same_v<Protocol, asio::ip::tcp>) {
      if (identity_.bySession) throw ApiError(403, "a login link is asked for with a token or on this machine");
      const auto host = request_[http::field::host];
      base = "http://" + std::string(host.data(), host.size());
    } else {
      const auto page = server_->loopbackPage();
      if (!page) {
        throw ApiError(409,
                       "the daemon has no TCP listener on this machine for a browser: add tcp://127.0.0.1:8730 to "
                       "listen in its configuration");
      }
      base = *page;
    }
    const std::string code = server_->newLoginCode(identity_.name);
    respond({201,
             {{"url", base + "/login?code=" + code},
              {"page", base + "/"},
              {"user", identity_.name},
              {"expires_in", std::chrono::seconds(kLoginLinkLasts).count()}}});
  }

  Submission submission() const {
    Submission submission;
    submission.owner = identity_.name;
    const auto type = request_[http::field::content_type];
    if (const auto boundary = multipartBoundary(std::string_view(type.data(), type.size()))) {
      std::vector<FormPart> parts;
      try {
        parts = parseMultipart(request_.body(), *boundary);
      } catch (const std::invalid_argument& malformed) {
        throw ApiError(400, fmt::format("malformed multipart body: {}", malformed.what()));
      }
      bool file = false;
      for (const FormPart& part : parts) {
        if (part.name == "file" || part.name == "mesh") {
          if (!part.fileName || part.fileName->empty()) throw ApiError(400, "the file part has no filename");
          submission.fileName = *part.fileName;
          submission.bytes = std::string(part.bytes);
          file = true;
        } else if (part.name == "options") {
          const json options = json::parse(part.bytes, nullptr, false);
          if (options.is_discarded()) throw ApiError(400, "options: not valid JSON");
          submission.options = optionWords(options);
        } else if (part.name == "device") {
          submission.device = std::string(part.bytes);
        } else if (part.name == "priority") {
          submission.priority = priorityOf(json(std::string(part.bytes)));
        } else {
          throw ApiError(400, fmt::format("unknown form field \"{}\" (file, options, device, priority)", part.name));
        }
      }
      if (!file) throw ApiError(400, "the form has no file part (the mesh, as file=@bunny.obj)");
      return submission;
    }
    const json body = bodyJson();
    for (const auto& [key, value] : body.items()) {
      if (key != "path" && key != "options" && key != "device" && key != "priority") {
        throw ApiError(400, fmt::format("unknown field \"{}\" (path, options, device, priority)", key));
      }
    }
    if (std::is_same_v<Protocol, asio::ip::tcp> && body.contains("path")) {
      throw ApiError(403,
                     "a path on the daemon's machine can be submitted over its Unix socket only; over TCP, upload "
                     "the mesh (a multipart form with file=@MESH)");
    }
    if (!body.contains("path") || !body["path"].is_string()) {
      throw ApiError(400,
                     "a submission is a multipart upload of the mesh (file=@MESH), or {\"path\": \"/abs/path\"} of a "
                     "mesh or a `make` output folder on the daemon's machine");
    }
    submission.path = body["path"].get<std::string>();
    submission.options = optionWords(body.value("options", json()));
    if (body.contains("device")) {
      if (!body["device"].is_string()) throw ApiError(400, "device: expected a device's name");
      submission.device = body["device"].get<std::string>();
    }
    submission.priority = priorityOf(body.value("priority", json()));
    return submission;
  }

  void fail(int status, const std::string& message) {
    keepAlive_ = false;
    respond({status, {{"error", message}}});
  }

  void respond(Reply reply) {
    if (!reply.file.empty()) {
      std::ifstream in(reply.file, std::ios::binary);
      std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (!in.good() && !in.eof()) {
        reply = Reply{500, {{"error", fmt::format("{} cannot be read", reply.file.string())}}};
      } else {
        reply.contentType = contentTypeOf(reply.file);
        reply.text = std::move(bytes);
        reply.headers.emplace_back("Cache-Control", "no-cache");
      }
    }
    auto response = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(reply.status), 11);
    response->set(http::field::server, "rotafabd");
    // No other page may frame this one (clicks through a frame would act
    // with the page's session), nor a file be read as another type.
    response->set("X-Frame-Options", "DENY");
    response->set("Content-Security-Policy", "frame-ancestors 'none'");
    response->set("X-Content-Type-Options", "nosniff");
    response->set("Referrer-Policy", "no-referrer");
    response->set(http::field::content_type, reply.contentType.empty() ? "application/json" : reply.contentType);
    for (const auto& [field, value] : reply.headers) response->set(field, value);
    response->body() = reply.text.empty() && reply.contentType.empty()
                           ? reply.body.dump(-1, ' ', false, json::error_handler_t::replace) + "\n"
                           : std::move(reply.text);
    const bool keep = keepAlive_ && request_.keep_alive() && reply.status < 400;
    response->keep_alive(keep);
    response->prepare_payload();
    stream_.expires_after(server_->limits.body);
    http::async_write(stream_, *response,
                      [self = this->shared_from_this(), response, keep](beast::error_code error, size_t) {
                        if (error || !keep) return self->close();
                        self->request_ = {};
                        self->readHeader(false);
                      });
  }

  // ---- the event stream (server-sent events) ----

  void startEvents(const std::string& target) {
    std::string query;
    pathParts(target, query);
    const std::string job = queryValue(query, "job");
    if (!job.empty()) {
      const auto id = wholeNumber(job);
      if (!id) return fail(400, fmt::format("job={}: expected a job number", job));
      onlyJob_ = *id;
    }
    stream_.expires_never();
    queue_.push_back(
        "HTTP/1.1 200 OK\r\nServer: rotafabd\r\nContent-Type: text/event-stream\r\nCache-Control: no-cache\r\n"
        "Connection: close\r\n\r\n: rotafabd events\n\n");
    writeNext();
    auto weak = std::weak_ptr<Session>(this->shared_from_this());
    const auto executor = stream_.get_executor();
    subscription_ = server_->service.subscribe([weak, executor, onlyJob = onlyJob_](const ServiceEvent& event) {
      if (onlyJob && event.type != "device" &&
          event.data.value("job", event.data.value("id", int64_t{0})) != *onlyJob) {
        return;
      }
      std::string text = fmt::format("event: {}\ndata: {}\n\n", event.type,
                                     event.data.dump(-1, ' ', false, json::error_handler_t::replace));
      asio::post(executor, [weak, text = std::move(text)]() mutable {
        if (auto self = weak.lock()) self->send(std::move(text));
      });
    });
    subscribed_ = true;
    heartbeat();
    // A client that goes away is seen as its end of the stream.
    stream_.socket().async_wait(Protocol::socket::wait_read,
                                [self = this->shared_from_this()](beast::error_code) { self->endEvents(); });
  }

  void heartbeat() {
    timer_ = std::make_unique<asio::steady_timer>(stream_.get_executor(), std::chrono::seconds(15));
    timer_->async_wait([weak = std::weak_ptr<Session>(this->shared_from_this())](beast::error_code error) {
      auto self = weak.lock();
      if (error || !self || self->ended_) return;
      self->send(": keep-alive\n\n");
      self->heartbeat();
    });
  }

  void send(std::string text) {
    if (ended_) return;
    // A client that does not read falls behind: it is dropped, not waited for.
    if (queue_.size() > 1000) return endEvents();
    queue_.push_back(std::move(text));
    if (queue_.size() == 1) writeNext();
  }

  void writeNext() {
    if (queue_.empty() || ended_) return;
    asio::async_write(stream_.socket(), asio::buffer(queue_.front()),
                      [self = this->shared_from_this()](beast::error_code error, size_t) {
                        if (error) return self->endEvents();
                        self->queue_.pop_front();
                        self->writeNext();
                      });
  }

  void endEvents() {
    if (ended_) return;
    ended_ = true;
    if (subscribed_) server_->service.unsubscribe(subscription_);
    if (timer_) timer_->cancel();
    close();
  }

  Stream stream_;
  std::shared_ptr<HttpServer::Impl> server_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::empty_body>> header_;
  std::optional<http::request_parser<http::string_body>> body_;
  http::request<http::string_body> request_;
  Identity identity_;
  bool overLimit_ = false, keepAlive_ = true;
  // The event stream's.
  std::optional<int64_t> onlyJob_;
  std::deque<std::string> queue_;
  size_t subscription_ = 0;
  bool subscribed_ = false, ended_ = false;
  std::unique_ptr<asio::steady_timer> timer_;
};

template <typename Acceptor, typename Protocol>
void acceptLoop(Acceptor& acceptor, std::shared_ptr<HttpServer::Impl> server) {
  acceptor.async_accept([&acceptor, server](beast::error_code error, typename Protocol::socket socket) {
    if (error == asio::error::operation_aborted || server->closing) return;
    if (!error) {
      const bool overLimit = server->connections >= server->service.config().connectionLimit;
      auto session = std::make_shared<Session<Protocol>>(std::move(socket), server);
      if (server->open.size() >= 2 * server->service.config().connectionLimit) {
        std::erase_if(server->open, [](const auto& weak) { return weak.expired(); });
      }
      server->open.push_back(session);
      session->start(overLimit);
    } else {
      server->log->warn("accept: {}", error.message());
    }
    acceptLoop<Acceptor, Protocol>(acceptor, server);
  });
}

}  // namespace

HttpServer::HttpServer(asio::io_context& io, Service& service, std::shared_ptr<spdlog::logger> log, HttpLimits limits)
    : impl_(std::make_shared<Impl>(io, service, std::move(log), limits)) {}

HttpServer::~HttpServer() { close(); }

void HttpServer::listen() {
  for (const std::string& address : impl_->service.config().listen) {
    try {
      if (address.starts_with("unix:")) {
        const fs::path path = address.substr(5);
        std::error_code error;
        fs::create_directories(path.parent_path(), error);
        ::chmod(path.parent_path().c_str(), 0700);
        // A socket file left by a daemon that was killed: nobody answers on it (the state lock says no daemon runs).
        fs::remove(path, error);
        auto acceptor = std::make_unique<asio::local::stream_protocol::acceptor>(impl_->io);
        const asio::local::stream_protocol::endpoint endpoint(path.string());
        acceptor->open(endpoint.protocol());
        // Only this user may connect: mode 0600 from the moment the socket exists.
        const mode_t previous = ::umask(0177);
        beast::error_code bindError;
        acceptor->bind(endpoint, bindError);
        ::umask(previous);
        if (bindError) throw boost::system::system_error(bindError);
        acceptor->listen(asio::socket_base::max_listen_connections);
        impl_->socketFiles.push_back(path);
        impl_->bound.push_back(address);
        acceptLoop<asio::local::stream_protocol::acceptor, asio::local::stream_protocol>(*acceptor, impl_);
        impl_->unixAcceptors.push_back(std::move(acceptor));
      } else {
        const std::string rest = address.substr(6);
        const size_t colon = rest.rfind(':');
        std::string host = rest.substr(0, colon);
        if (host.starts_with("[")) host = host.substr(1, host.size() - 2);
        if (host == "localhost") host = "127.0.0.1";
        const auto port = static_cast<unsigned short>(std::stoi(rest.substr(colon + 1)));
        auto acceptor = std::make_unique<asio::ip::tcp::acceptor>(impl_->io);
        const asio::ip::tcp::endpoint endpoint(asio::ip::make_address(host), port);
        acceptor->open(endpoint.protocol());
        acceptor->set_option(asio::socket_base::reuse_address(true));
        beast::error_code bindError;
        acceptor->bind(endpoint, bindError);
        if (bindError == asio::error::address_in_use && impl_->service.config().defaultListen) {
          // The default port taken (another daemon, another program): any
          // free one, which rotafabd.json records and `rotafab dashboard` reads.
          impl_->log->warn("{}: the port is in use; the page is on another port (rotafabd.json, rotafab dashboard)",
                           address);
          bindError = {};
          acceptor->bind(asio::ip::tcp::endpoint(endpoint.address(), 0), bindError);
        }
        if (bindError) throw boost::system::system_error(bindError);
        acceptor->listen(asio::socket_base::max_listen_connections);
        const auto local = acceptor->local_endpoint();
        impl_->bound.push_back(fmt::format("tcp://{}:{}", local.address().to_string(), local.port()));
        acceptLoop<asio::ip::tcp::acceptor, asio::ip::tcp>(*acceptor, impl_);
        impl_->tcpAcceptors.push_back(std::move(acceptor));
      }
    } catch (const std::exception& error) {
      throw std::runtime_error(fmt::format("{}: cannot listen: {}", address, error.what()));
    }
  }
}

void HttpServer::close() {
  if (!impl_ || impl_->closing) return;
  impl_->closing = true;
  beast::error_code ignored;
  for (auto& acceptor : impl_->unixAcceptors) acceptor->close(ignored);
  for (auto& acceptor : impl_->tcpAcceptors) acceptor->close(ignored);
  for (const fs::path& file : impl_->socketFiles) {
    std::error_code error;
    fs::remove(file, error);
  }
  for (const auto& weak : impl_->open) {
    if (auto connection = weak.lock()) connection->close();
  }
  impl_->open.clear();
}

std::vector<std::string> HttpServer::addresses() const { return impl_->bound; }

}  // namespace rotafab::service
