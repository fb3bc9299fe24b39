#include "daemon/service/HttpServer.h"

#include <fmt/format.h>
#include <pwd.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <utility>

#include "daemon/service/AccessGate.h"
#include "daemon/service/ApiInput.h"
#include "daemon/service/EventStream.h"
#include "daemon/service/HttpRoutes.h"
#include "daemon/service/UploadForm.h"

namespace rotafab::service {
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A TCP peer address's connections that no request has yet shown a token
// or session on: a program that opens many and sends nothing has no more
// than these (and all such together no more than half of connection_limit),
// and never any of the Unix socket's, which has a limit of its own. Past a
// limit, a new connection takes the place of the oldest of them that is
// idle (waiting for a request with nothing unread, or closing after a
// refusal): every program on loopback shares one address, so a token
// holder's new connection must never be refused for a stranger's idle ones.
constexpr size_t kUnknownPerPeer = 16;
// A connection closed on a refusal is read from (and what it sends thrown
// away) for this long or this much at most, so that its client reads the
// refusal rather than a reset.
constexpr auto kLingerFor = std::chrono::seconds(2);
constexpr size_t kLingerBytes = 1 << 20;
// An upload is read this much at a time, and written before the next piece is read.
constexpr size_t kUploadPiece = 64 * 1024;

std::optional<std::string> accountName(uid_t uid) {
  struct passwd entry {};
  struct passwd* found = nullptr;
  char buffer[4096];
  if (::getpwuid_r(uid, &entry, buffer, sizeof buffer, &found) == 0 && found) return std::string(found->pw_name);
  return std::nullopt;
}

bool isLoopback(const asio::ip::address& address) {
  return address.is_loopback() || (address.is_v6() && address.to_v6().is_v4_mapped() &&
                                   asio::ip::make_address_v4(asio::ip::v4_mapped, address.to_v6()).is_loopback());
}

}  // namespace

struct HttpServer::Impl : std::enable_shared_from_this<HttpServer::Impl> {
  Impl(asio::io_context& io, Service& service, std::shared_ptr<spdlog::logger> log, HttpLimits limits)
      : io(io), service(service), log(std::move(log)), limits(limits), gate(service.config()) {
    for (const fs::path& folder : {service.config().stateDir, service.config().spool, pages, fs::path(kThreeFolder)}) {
      std::string text = folder.lexically_normal().string();
      while (text.size() > 1 && text.back() == '/') text.pop_back();
      if (!text.empty()) hidden.push_back(text);
    }
  }

  asio::io_context& io;
  Service& service;
  std::shared_ptr<spdlog::logger> log;
  HttpLimits limits;
  fs::path pages = pageFolder();
  AccessGate gate;
  std::vector<std::string> hidden;  // folders no client is told of (withoutDaemonPaths)
  std::vector<std::unique_ptr<asio::local::stream_protocol::acceptor>> unixAcceptors;
  std::vector<std::unique_ptr<asio::ip::tcp::acceptor>> tcpAcceptors;
  std::vector<fs::path> socketFiles;
  std::vector<std::string> bound;
  bool closing = false;
  // The connections open, counted apart: the owner's socket is never short
  // of room because of TCP, and callers nobody knows yet have less of TCP.
  size_t unixConnections = 0, tcpConnections = 0, tcpUnknown = 0;
  std::map<asio::ip::address, size_t> unknownByPeer;
  // Uploads are written here, a piece at a time, never on the I/O thread
  // (a spool on a slow disk would hold up every connection, the owner's too).
  asio::thread_pool disk{1};
  // Every connection, to close them all at shutdown.
  struct Connection {
    virtual ~Connection() = default;
    virtual void close() = 0;
    // Whether it is a TCP connection that can give its place to a new one:
    // idle, and a stranger's (or closing); from `peer` if one is named.
    // `midHeader`: a stranger's that has sent part of a request's header counts too.
    [[nodiscard]] virtual bool idle(const asio::ip::address* /*peer*/, bool /*strangersOnly*/,
                                    bool /*midHeader*/) const {
      return false;
    }
    virtual void evict() {}
  };
  std::vector<std::weak_ptr<Connection>> open;

  // Closes the oldest idle connection that `idle(peer, strangersOnly)`
  // picks; failing that, the oldest stranger's that is still sending its
  // request's header (a header sent a byte at a time must not hold a place
  // a token holder's request needs: a real client sends its header at once,
  // so the newest connection, the one that asks for room, is its); whether there was one.
  bool evictOldest(const asio::ip::address* peer, bool strangersOnly) {
    for (const bool midHeader : {false, true}) {
      for (const auto& weak : open) {
        if (auto connection = weak.lock(); connection && connection->idle(peer, strangersOnly, midHeader)) {
          connection->evict();
          return true;
        }
      }
    }
    return false;
  }

  // The names of the users who connected lately, on the I/O thread: a
  // lookup reads /etc/passwd through NSS, on every connection. A minute
  // old at most, so that a renamed account is seen under its new name.
  static constexpr auto kNameKeptFor = std::chrono::seconds(60);
  std::unordered_map<uid_t, std::pair<std::string, std::chrono::steady_clock::time_point>> names;

  std::optional<Caller> peerOf(asio::local::stream_protocol::socket& socket) {
    struct ucred credentials {};
    socklen_t size = sizeof credentials;
    if (::getsockopt(socket.native_handle(), SOL_SOCKET, SO_PEERCRED, &credentials, &size) != 0) return std::nullopt;
    const auto now = std::chrono::steady_clock::now();
    auto known = names.find(credentials.uid);
    if (known == names.end() || now - known->second.second > kNameKeptFor) {
      const auto found = accountName(credentials.uid);
      // Not found, perhaps only for now: not kept, asked again next time.
      if (!found) return Caller{fmt::format("uid {}", credentials.uid), false};
      known = names.insert_or_assign(credentials.uid, std::pair{*found, now}).first;
    }
    return Caller{known->second.first, false};
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
  static constexpr bool kTcp = std::is_same_v<Protocol, asio::ip::tcp>;

 public:
  using Stream = beast::basic_stream<Protocol>;
  Session(typename Protocol::socket socket, std::shared_ptr<HttpServer::Impl> server, Listener listener)
      : stream_(std::move(socket)), server_(std::move(server)), listener_(listener) {}

  void start() {
    HttpServer::Impl& server = *server_;
    const size_t limit = server.service.config().connectionLimit;
    std::string full;
    if constexpr (kTcp) {
      beast::error_code error;
      peer_ = stream_.socket().remote_endpoint(error).address();
      counted_ = true;
      ++server.tcpConnections;
      ++server.tcpUnknown;
      ++server.unknownByPeer[peer_];
      // Room is made by closing idle strangers' connections, oldest first;
      // only when every one is at work is the new one refused.
      while (server.unknownByPeer[peer_] > kUnknownPerPeer) {
        if (!server.evictOldest(&peer_, true)) {
          full = fmt::format("{} has {} connections without a token or session at work; try again shortly",
                             peer_.to_string(), kUnknownPerPeer);
          break;
        }
      }
      while (full.empty() && server.tcpUnknown > std::max<size_t>(1, limit / 2)) {
        if (!server.evictOldest(nullptr, true)) {
          full = fmt::format(
              "the daemon serves {} TCP connections without a token or session at once; try again "
              "shortly",
              std::max<size_t>(1, limit / 2));
        }
      }
      while (full.empty() && server.tcpConnections > limit) {
        if (!server.evictOldest(nullptr, false)) {
          full = fmt::format("the daemon serves {} TCP connections at once; try again shortly", limit);
        }
      }
    } else {
      counted_ = true;
      if (++server.unixConnections > limit) {
        full = fmt::format("the daemon serves {} connections on its socket at once; try again shortly", limit);
      }
      peerCaller_ = server.peerOf(stream_.socket());
    }
    if (!full.empty()) return fail(503, full);  // at once: not a byte of the request is waited for
    readHeader(true);
  }

  ~Session() override { uncount(); }

  [[nodiscard]] bool idle(const asio::ip::address* peer, bool strangersOnly, bool midHeader) const override {
    if constexpr (kTcp) {
      if (!counted_ || (peer && *peer != peer_) || (strangersOnly && known_)) return false;
      if (lingering_) return true;
      if (midHeader) return waiting_ && !known_;
      // (A request already in the socket's buffer is not idle: it is read next.)
      beast::error_code error;
      return waiting_ && !known_ && buffer_.size() == 0 && stream_.socket().available(error) == 0 && !error;
    } else {
      return false;
    }
  }

  void evict() override {
    uncount();
    close();
  }

  void close() override {
    beast::error_code ignored;
    stream_.socket().shutdown(Protocol::socket::shutdown_both, ignored);
    stream_.socket().close(ignored);
  }

 private:
  // Its place given back (once: when it is evicted, or when it ends).
  void uncount() {
    if (!counted_) return;
    counted_ = false;
    if constexpr (kTcp) {
      --server_->tcpConnections;
      if (!known_) unknownGone();
    } else {
      --server_->unixConnections;
    }
  }

  void unknownGone() {
    --server_->tcpUnknown;
    if (auto found = server_->unknownByPeer.find(peer_);
        found != server_->unknownByPeer.end() && --found->second == 0) {
      server_->unknownByPeer.erase(found);
    }
  }

  void readHeader(bool first) {
    header_.emplace();
    header_->header_limit(static_cast<std::uint32_t>(server_->limits.headerBytes));
    // (The gate judges the body's size, by route; the parser is not to refuse it first.)
    header_->body_limit(std::numeric_limits<std::uint64_t>::max());
    stream_.expires_after(first ? server_->limits.header : server_->limits.idle);
    waiting_ = true;
    http::async_read_header(stream_, buffer_, *header_,
                            [self = this->shared_from_this(), first](beast::error_code error, size_t) {
                              self->waiting_ = false;
                              self->onHeader(error, first);
                            });
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
    if (error) return fail(400, fmt::format("malformed request: {}", error.message()));
    const auto& request = header_->get();
    const RequestHead head = requestHead(*header_);
    keepAlive_ = request.keep_alive();
    method_ = request.method();
    host_ = std::string(head.host);
    expectsContinue_ = beast::iequals(request[http::field::expect], "100-continue");
    try {
      admitted_ = server_->gate.admit(head, listener_, peerCaller_);
    } catch (const ApiError& refused) {
      return fail(refused.status, refused.what());
    }
    if constexpr (kTcp) {
      if (admitted_.caller && !known_) {
        known_ = true;
        if (counted_) unknownGone();
      }
    }
    switch (admitted_.body) {
      case BodyKind::None:
        if (admitted_.route.route == Route::Events) return startEvents();
        return dispatch(json());
      case BodyKind::Json:
        return readJson();
      case BodyKind::JsonOrForm:
        return readUpload();
    }
  }

  // What the caller is told to send its body (curl waits a second for it before it sends a large one).
  template <typename Next>
  void continueThen(Next next) {
    if (!expectsContinue_) return next();
    auto continued = std::make_shared<std::string>("HTTP/1.1 100 Continue\r\n\r\n");
    asio::async_write(stream_, asio::buffer(*continued),
                      [self = this->shared_from_this(), continued, next](beast::error_code written, size_t) {
                        if (written) return self->close();
                        next();
                      });
  }

  void readJson() {
    json_.emplace(std::move(*header_));
    json_->body_limit(admitted_.bodyLimit);
    stream_.expires_after(server_->limits.body);
    continueThen([self = this->shared_from_this()] {
      http::async_read(self->stream_, self->buffer_, *self->json_, [self](beast::error_code error, size_t) {
        if (self->bodyFailed(error)) return;
        const std::string& text = self->json_->get().body();
        json body = text.empty() ? json::object() : json::parse(text, nullptr, false);
        if (body.is_discarded()) return self->fail(400, "the body is not valid JSON");
        if (!body.is_object()) return self->fail(400, "the body must be a JSON object");
        self->json_.reset();
        self->dispatch(std::move(body));
      });
    });
  }

  // Whether reading a body failed (and the caller was told, or the connection closed).
  bool bodyFailed(beast::error_code error) {
    if (!error) return false;
    if (error == http::error::body_limit) {
      fail(413,
           fmt::format("the body is larger than the {} bytes {} takes", admitted_.bodyLimit, admitted_.target.path()));
    } else if (error == beast::error::timeout) {
      server_->log->info("a client did not send its request's body in time; closed");
      fail(408, "the request's body did not come in time");
    } else if (error.category() == http::make_error_code(http::error::bad_chunk).category() &&
               error != http::error::partial_message) {
      // A body that does not keep to its framing (a bad chunk size, say): told, not dropped.
      fail(400, fmt::format("malformed body: {}", error.message()));
    } else {
      close();  // the caller went away
    }
    return true;
  }

  // ---- an upload, streamed into the spool ----

  void readUpload() {
    try {
      form_ = std::make_shared<UploadForm>(server_->service.beginUpload(), admitted_.boundary);
    } catch (const ApiError& refused) {
      return fail(refused.status, refused.what());
    }
    piece_.resize(kUploadPiece);
    upload_.emplace(std::move(*header_));
    upload_->body_limit(admitted_.bodyLimit);
    stream_.expires_after(server_->limits.body);
    continueThen([self = this->shared_from_this()] { self->readPiece(); });
  }

  void readPiece() {
    auto& body = upload_->get().body();
    body.data = piece_.data();
    body.size = piece_.size();
    http::async_read(stream_, buffer_, *upload_, [self = this->shared_from_this()](beast::error_code error, size_t) {
      if (error == http::error::need_buffer) error = {};
      if (self->bodyFailed(error)) return;
      const size_t got = self->piece_.size() - self->upload_->get().body().size;
      const bool last = self->upload_->is_done();
      // Written on the disk thread; the next piece is read once it is.
      asio::post(self->server_->disk, [self, got, last] {
        std::optional<Reply> refused;
        auto submission = std::make_shared<std::optional<Submission>>();
        try {
          self->form_->feed(std::string_view(self->piece_.data(), got));
          if (last) submission->emplace(self->form_->finish(self->admitted_.caller->name));
        } catch (const ApiError& error) {
          refused = Reply{error.status, {{"error", error.what()}}};
        } catch (const std::exception& error) {
          refused = Reply{500, {{"error", error.what()}}};
        }
        if (refused || last) self->form_.reset();  // (an unfinished entry goes with it)
        asio::post(self->stream_.get_executor(), [self, refused, submission, last]() mutable {
          if (refused) return self->fail(refused->status, refused->body.value("error", ""));
          if (!last) return self->readPiece();
          self->upload_.reset();
          self->stream_.expires_never();
          self->server_->service.submit(std::move(**submission), self->replier());
        });
      });
    });
  }

  // ---- what each route answers ----

  // The reply reaches the session on its own executor, whichever thread the service answered on.
  ReplyHandler replier() {
    return [self = this->shared_from_this()](Reply reply) {
      asio::post(self->stream_.get_executor(),
                 [self, reply = std::move(reply)]() mutable { self->respond(std::move(reply)); });
    };
  }

  void dispatch(json body) {
    header_.reset();
    try {
      route(std::move(body));
    } catch (const ApiError& refused) {
      respond({refused.status, {{"error", refused.what()}}});
    } catch (const std::exception& failure) {
      respond({400, {{"error", failure.what()}}});
    }
  }

  void route(const json& body) {
    const RouteCall call{server_->service,
                         server_->gate,
                         admitted_,
                         method_ == http::verb::get,
                         kTcp,
                         host_,
                         server_->loopbackPage(),
                         server_->pages,
                         [this](Reply reply) { respond(std::move(reply)); },
                         replier()};
    answerRoute(call, body);
  }

  // ---- replies ----

  // A refusal: the caller is told, and the connection closes without its body being read.
  void fail(int status, const std::string& message) {
    keepAlive_ = false;
    respond({status, {{"error", message}}});
  }

  template <typename Response>
  void decorate(Response& response, const Reply& reply) {
    response.set(http::field::server, "rotafabd");
    // No other page may frame this one (clicks through a frame would act
    // with the page's session), nor a file be read as another type.
    response.set("X-Frame-Options", "DENY");
    response.set("Content-Security-Policy", "frame-ancestors 'none'");
    response.set("X-Content-Type-Options", "nosniff");
    response.set("Referrer-Policy", "no-referrer");
    for (const auto& [field, value] : reply.headers) response.set(field, value);
  }

  void respond(Reply reply) {
    if (!reply.file.empty()) return respondFile(std::move(reply));
    if (reply.status >= 400 && reply.body.is_object() && reply.body.contains("error") &&
        reply.body["error"].is_string()) {
      // Whatever the failure said, a caller learns nothing of where the daemon keeps its files.
      reply.body["error"] = withoutDaemonPaths(reply.body["error"].get<std::string>(), server_->hidden);
    }
    auto response = std::make_shared<http::response<http::string_body>>(static_cast<http::status>(reply.status), 11);
    decorate(*response, reply);
    response->set(http::field::content_type, reply.contentType.empty() ? "application/json" : reply.contentType);
    response->body() = reply.text.empty() && reply.contentType.empty()
                           ? reply.body.dump(-1, ' ', false, json::error_handler_t::replace) + "\n"
                           : std::move(reply.text);
    send(std::move(response), reply.status);
  }

  // A file's bytes, read from disk as they are sent.
  void respondFile(Reply reply) {
    beast::error_code error;
    http::file_body::value_type body;
    body.open(reply.file.c_str(), beast::file_mode::scan, error);
    if (error) {
      server_->log->error("{}: {}", reply.file.string(), error.message());
      return respond({500, {{"error", fmt::format("{} cannot be read", reply.file.filename().string())}}});
    }
    auto response = std::make_shared<http::response<http::file_body>>(
        std::piecewise_construct, std::make_tuple(std::move(body)), std::make_tuple(http::status::ok, 11));
    decorate(*response, reply);
    response->set(http::field::content_type, contentTypeOf(reply.file));
    response->set(http::field::cache_control, "no-cache");
    send(std::move(response), 200);
  }

  template <typename Response>
  void send(std::shared_ptr<Response> response, int status) {
    const bool keep = keepAlive_ && status < 400;
    response->keep_alive(keep);
    response->prepare_payload();
    stream_.expires_after(server_->limits.body);
    http::async_write(stream_, *response,
                      [self = this->shared_from_this(), response, keep](beast::error_code error, size_t) {
                        if (error) return self->close();
                        if (!keep) return self->linger();
                        self->readHeader(false);
                      });
  }

  // The reply sent, the connection is closed for sending; what the caller
  // still sends (a body never read) is read and thrown away for a moment, so
  // that its client sees the reply rather than a reset, then it is closed.
  void linger() {
    lingering_ = true;
    beast::error_code ignored;
    stream_.socket().shutdown(Protocol::socket::shutdown_send, ignored);
    stream_.expires_after(kLingerFor);
    drainSome();
  }

  void drainSome() {
    stream_.async_read_some(asio::buffer(drain_), [self = this->shared_from_this()](beast::error_code error, size_t n) {
      self->drained_ += n;
      if (error || self->drained_ > kLingerBytes) return self->close();
      self->drainSome();
    });
  }

  // ---- the event stream (server-sent events) ----

  void startEvents() {
    std::optional<int64_t> onlyJob;
    const std::string job = queryValue(admitted_.target.query, "job");
    if (!job.empty()) {
      const auto id = wholeNumberIn(job, kJobField);
      if (!id) return fail(400, fmt::format("job={}: expected a job number", shownText(job, 40)));
      onlyJob = *id;
    }
    header_.reset();
    stream_.expires_never();
    auto self = this->shared_from_this();
    std::make_shared<EventStream<typename Protocol::socket>>(stream_.socket(), server_->service, onlyJob, self,
                                                             [session = self.get()] { session->close(); })
        ->start();
  }

  Stream stream_;
  std::shared_ptr<HttpServer::Impl> server_;
  Listener listener_;
  asio::ip::address peer_;
  std::optional<Caller> peerCaller_;
  bool counted_ = false, known_ = false, keepAlive_ = true, expectsContinue_ = false;
  bool waiting_ = false, lingering_ = false;  // for a request's header; after a refusal
  beast::flat_buffer buffer_{64 * 1024};
  std::optional<http::request_parser<http::empty_body>> header_;
  std::optional<http::request_parser<http::string_body>> json_;
  std::optional<http::request_parser<http::buffer_body>> upload_;
  Admission admitted_;
  http::verb method_ = http::verb::unknown;
  std::string host_;
  std::shared_ptr<UploadForm> form_;
  std::vector<char> piece_;
  std::array<char, 4096> drain_{};
  size_t drained_ = 0;
};

template <typename Acceptor, typename Protocol>
void acceptLoop(Acceptor& acceptor, std::shared_ptr<HttpServer::Impl> server, Listener listener) {
  acceptor.async_accept([&acceptor, server, listener](beast::error_code error, typename Protocol::socket socket) {
    if (error == asio::error::operation_aborted || server->closing) return;
    if (!error) {
      auto session = std::make_shared<Session<Protocol>>(std::move(socket), server, listener);
      if (server->open.size() >= 4 * server->service.config().connectionLimit) {
        std::erase_if(server->open, [](const auto& weak) { return weak.expired(); });
      }
      server->open.push_back(session);
      session->start();
    } else {
      server->log->warn("accept: {}", error.message());
    }
    acceptLoop<Acceptor, Protocol>(acceptor, server, listener);
  });
}

}  // namespace

HttpServer::HttpServer(asio::io_context& io, Service& service, std::shared_ptr<spdlog::logger> log, HttpLimits limits)
    : impl_(std::make_shared<Impl>(io, service, std::move(log), limits)) {}

HttpServer::~HttpServer() {
  close();
  impl_->disk.join();
}

void HttpServer::listen() {
  const DaemonConfig& config = impl_->service.config();
  for (const std::string& address : config.listen) {
    try {
      if (address.starts_with("unix:")) {
        const fs::path path = address.substr(5);
        std::error_code error;
        // The socket's folder: made private when the daemon makes it (or it
        // is the default's, the daemon's own); one the user named is left as found.
        const bool existed = fs::is_directory(path.parent_path(), error);
        fs::create_directories(path.parent_path(), error);
        if (!existed || config.defaultListen) ::chmod(path.parent_path().c_str(), 0700);
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
        acceptLoop<asio::local::stream_protocol::acceptor, asio::local::stream_protocol>(*acceptor, impl_,
                                                                                         Listener{true, false});
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
        if (bindError == asio::error::address_in_use && config.defaultListen) {
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
        acceptLoop<asio::ip::tcp::acceptor, asio::ip::tcp>(*acceptor, impl_,
                                                           Listener{false, isLoopback(endpoint.address())});
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
