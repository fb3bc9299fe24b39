#pragma once
// The one gate every request passes before the daemon routes it or reads a
// byte of its body (docs/SECURITY.md). From the request's header alone it
// decides, in this order:
//   1. the path, normalised (RequestTarget.h): what the rest reads;
//   2. on a loopback listener, a Host that names this machine (a page whose
//      name was made to point at 127.0.0.1, DNS rebinding, is refused);
//   3. who asks: over the Unix socket, the peer's credentials (the socket is
//      the daemon user's alone); over TCP, a bearer token of the
//      configuration or a browser session's secret, in the Authorization
//      header (a session's also in the event stream's ?session=, which a
//      browser cannot send as a header). Only the endpoints ApiRoutes.h
//      marks open are served to a caller nobody knows; anything else,
//      unknown paths included, is 401 for them;
//   4. the route and method (404, 405);
//   5. over TCP, for a request that changes something, that it does not
//      come from another site's page: its Origin is the listener's own (or
//      one of the configuration's `origins`, behind a reverse proxy), and
//      Sec-Fetch-Site, when sent, is same-origin;
//   6. the body the endpoint takes: none, JSON of at most 64 KiB, or a
//      multipart form of at most upload_limit; over TCP, a content type a
//      cross-site form can send (text/plain, urlencoded) is refused, as is
//      everywhere a body larger than the endpoint takes, from its Content-Length.
// Throws ApiError with the refusal; the server sends it and closes the
// connection without reading the body.
//
// Threads: used on the server's one I/O thread only (its sessions are not locked).

#include <boost/beast/http/empty_body.hpp>
#include <boost/beast/http/parser.hpp>
#include <boost/beast/http/verb.hpp>
#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "daemon/service/ApiRoutes.h"
#include "daemon/service/DaemonConfig.h"
#include "daemon/service/RequestTarget.h"

namespace rotafab::service {

// Who asks, once the gate knows.
struct Caller {
  std::string name;        // the owner of what they submit
  bool bySession = false;  // a browser's session (which may not ask for login links)
};

// What the gate reads of a request: its header's fields.
struct RequestHead {
  boost::beast::http::verb method = boost::beast::http::verb::unknown;
  std::string_view target, host, origin, fetchSite, contentType, authorization, transferEncoding;
  std::optional<uint64_t> contentLength;  // none: no Content-Length
  bool chunked = false;
  // A field that decides who asks or how the body is read, sent more than
  // once (which of two a proxy and the daemon would each take is anyone's guess).
  std::string_view repeated;
};

// What the gate reads of a parsed header; its views point into `parser`'s.
RequestHead requestHead(const boost::beast::http::request_parser<boost::beast::http::empty_body>& parser);

struct Listener {
  bool unixSocket = false;  // the daemon's Unix socket
  bool loopback = false;    // a TCP listener on 127.0.0.1 or ::1
};

// A request the gate let through, and what it may send.
struct Admission {
  RequestTarget target;
  MatchedRoute route;
  std::optional<Caller> caller;  // none on an open endpoint, for a caller nobody knows
  BodyKind body = BodyKind::None;
  std::string boundary;  // a multipart form's
  uint64_t bodyLimit = 0;
};

class AccessGate {
 public:
  explicit AccessGate(const DaemonConfig& config);

  // `peer`: over the Unix socket, who its credentials say connected (none
  // when they could not be read). Throws ApiError.
  Admission admit(const RequestHead& head, const Listener& listener, const std::optional<Caller>& peer);

  // A one-time login link's code for `name`, valid kLoginLinkLasts.
  std::string newLoginCode(const std::string& name);
  // The secret of a new session for the code's holder; none when the code is unknown, used or old.
  std::optional<std::string> openSession(const std::string& code);

  static constexpr auto kLoginLinkLasts = std::chrono::minutes(5);
  static constexpr auto kSessionLasts = std::chrono::hours(24 * 7);  // unused for this long, a session ends

 private:
  using Clock = std::chrono::steady_clock;
  std::optional<Caller> callerOverTcp(const RequestHead& head, const RequestTarget& target, Route route,
                                      std::string& refusal);
  void checkSameOrigin(const RequestHead& head) const;
  void checkHost(const RequestHead& head) const;
  static void checkFraming(const RequestHead& head);

  std::vector<TokenConfig> tokens_;
  std::vector<std::string> origins_;  // lower case, as a browser sends them
  uint64_t uploadLimit_;
  // One-time login links (code -> who, until when) and the sessions they
  // opened (secret -> who, last used); in memory: a daemon started again
  // asks everyone to sign in again.
  std::unordered_map<std::string, std::pair<std::string, Clock::time_point>> loginCodes_;
  std::unordered_map<std::string, std::pair<std::string, Clock::time_point>> sessions_;
};

// 32 random bytes from OpenSSL's generator, as hex: a login code or a session's secret.
std::string randomSecret();

// The host of a Host header or an origin, lower case, without its port or brackets ("[::1]:8730" -> "::1").
std::string hostName(std::string_view hostAndPort);

}  // namespace rotafab::service
