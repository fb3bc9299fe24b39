#include "daemon/service/AccessGate.h"

#include <fmt/format.h>
#include <openssl/rand.h>

#include <algorithm>
#include <cctype>
#include <charconv>

#include "daemon/service/ApiError.h"
#include "daemon/service/ApiInput.h"
#include "daemon/service/Multipart.h"

namespace rotafab::service {
namespace http = boost::beast::http;

namespace {

// The media type of a Content-Type, lower case, without its parameters.
std::string mediaType(std::string_view contentType) {
  std::string type = asciiLower(contentType.substr(0, contentType.find(';')));
  while (!type.empty() && (type.back() == ' ' || type.back() == '\t')) type.pop_back();
  while (!type.empty() && (type.front() == ' ' || type.front() == '\t')) type.erase(type.begin());
  return type;
}

// 127.0.0.1 to 127.255.255.255 written as four decimal numbers (not 127.1, not 0x7f.1).
bool isLoopbackQuad(std::string_view name) {
  int parts = 0;
  while (!name.empty()) {
    const size_t dot = name.find('.');
    const std::string_view part = name.substr(0, dot);
    unsigned value = 256;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || part.size() > 3 || error != std::errc() || end != part.data() + part.size() || value > 255 ||
        (parts == 0 && value != 127)) {
      return false;
    }
    ++parts;
    if (dot == std::string_view::npos) break;
    name.remove_prefix(dot + 1);
    if (name.empty()) return false;
  }
  return parts == 4;
}

// A Host header of a loopback name (localhost, 127.x.y.z, [::1]) with at most a port of digits after it.
bool isLoopbackHost(std::string_view host) {
  std::string_view name = host, port;
  if (host.starts_with("[")) {
    const size_t close = host.find(']');
    if (close == std::string_view::npos) return false;
    name = host.substr(1, close - 1);
    port = host.substr(close + 1);
  } else if (const size_t colon = host.find(':'); colon != std::string_view::npos) {
    name = host.substr(0, colon);
    port = host.substr(colon);
  }
  if (!port.empty()) {
    if (port.size() < 2 || port.size() > 6 || port[0] != ':' ||
        port.substr(1).find_first_not_of("0123456789") != std::string_view::npos) {
      return false;
    }
  }
  const std::string lower = asciiLower(name);
  return host.starts_with("[") ? lower == "::1" : (lower == "localhost" || isLoopbackQuad(lower));
}

// Why a path nothing answers is not there, in a caller's words.
std::string notFound(const RequestTarget& target) {
  const auto& parts = target.parts;
  if (parts.size() == 4 && parts[0] == "api" && parts[1] == "jobs") {
    return fmt::format("no action {} (cancel, pause, resume, start, next, move, frame)", parts[3]);
  }
  if (!parts.empty() && parts[0] == "api") return fmt::format("no such resource: {}", target.path());
  return fmt::format("no such page: {} (the page is at /, the API under /api; see docs/API.md)", target.path());
}

}  // namespace

std::string randomSecret() {
  unsigned char bytes[32];
  if (RAND_bytes(bytes, sizeof bytes) != 1) throw ApiError(500, "no random bytes for a secret");
  std::string text;
  for (unsigned char byte : bytes) text += fmt::format("{:02x}", byte);
  return text;
}

std::string hostName(std::string_view hostAndPort) {
  if (const size_t scheme = hostAndPort.find("://"); scheme != std::string_view::npos) {
    hostAndPort = hostAndPort.substr(scheme + 3);
  }
  if (hostAndPort.starts_with("[")) {
    const size_t close = hostAndPort.find(']');
    return asciiLower(hostAndPort.substr(1, close == std::string_view::npos ? std::string_view::npos : close - 1));
  }
  return asciiLower(hostAndPort.substr(0, hostAndPort.find(':')));
}

RequestHead requestHead(const http::request_parser<http::empty_body>& parser) {
  const auto& request = parser.get();
  const auto view = [](boost::beast::string_view text) { return std::string_view(text.data(), text.size()); };
  RequestHead head;
  head.method = request.method();
  head.target = view(request.target());
  head.host = view(request[http::field::host]);
  head.origin = view(request[http::field::origin]);
  head.fetchSite = view(request["Sec-Fetch-Site"]);
  head.contentType = view(request[http::field::content_type]);
  head.authorization = view(request[http::field::authorization]);
  head.transferEncoding = view(request[http::field::transfer_encoding]);
  if (const auto length = parser.content_length()) head.contentLength = *length;
  head.chunked = parser.chunked();
  for (const std::string_view once :
       {"Host", "Authorization", "Origin", "Sec-Fetch-Site", "Content-Type", "Content-Length", "Transfer-Encoding"}) {
    if (request.count(boost::beast::string_view(once.data(), once.size())) > 1) {
      head.repeated = once;
      break;
    }
  }
  return head;
}

AccessGate::AccessGate(const DaemonConfig& config) : tokens_(config.tokens), uploadLimit_(config.uploadLimit) {
  for (const std::string& origin : config.origins) origins_.push_back(asciiLower(origin));
}

Admission AccessGate::admit(const RequestHead& head, const Listener& listener, const std::optional<Caller>& peer) {
  Admission admitted;
  checkFraming(head);
  admitted.target = parseTarget(head.target);
  if (listener.loopback) checkHost(head);
  const std::optional<MatchedRoute> route = matchRoute(admitted.target.parts);
  const Endpoint* endpoint = route ? endpointFor(route->route, head.method) : nullptr;
  if (listener.unixSocket) {
    admitted.caller = peer;
    if (!peer) throw ApiError(401, "the peer's credentials on the daemon's socket cannot be read");
  } else {
    std::string refusal;
    admitted.caller = callerOverTcp(head, admitted.target, route ? route->route : Route::About, refusal);
    // Nobody known: only the open endpoints, and not a word about the others.
    if (!admitted.caller && !(endpoint && endpoint->open)) throw ApiError(401, refusal);
  }
  if (!route) throw ApiError(404, notFound(admitted.target));
  if (!endpoint) {
    throw ApiError(405, fmt::format("{} takes {}", admitted.target.path(), methodsOf(route->route)));
  }
  admitted.route = *route;
  if (!listener.unixSocket && head.method != http::verb::get && head.method != http::verb::head) {
    checkSameOrigin(head);
  }
  const bool hasBody = head.chunked || (head.contentLength && *head.contentLength > 0);
  const std::string type = mediaType(head.contentType);
  const std::string said = fmt::format("{} {}", std::string(http::to_string(head.method)), admitted.target.path());
  switch (endpoint->body) {
    case BodyKind::None:
      if (hasBody) throw ApiError(400, fmt::format("{} takes no body", said));
      break;
    case BodyKind::JsonOrForm:
      if (type == "multipart/form-data") {
        const auto boundary = multipartBoundary(head.contentType);
        if (!boundary) throw ApiError(400, "a multipart form's Content-Type has no boundary (1 to 70 characters)");
        admitted.body = BodyKind::JsonOrForm;
        admitted.boundary = *boundary;
        admitted.bodyLimit = uploadLimit_;
        break;
      }
      [[fallthrough]];
    case BodyKind::Json:
      // (A form of another site's page can send text/plain, urlencoded and
      // multipart bodies without asking first; JSON it cannot. No page
      // reaches the Unix socket: there, a body is read as JSON whatever
      // its type, as `curl -d` sends it. No body at all is no arguments.)
      if (hasBody && !listener.unixSocket && type != "application/json") {
        throw ApiError(
            415, fmt::format(
                     "{} takes a JSON body, with Content-Type: application/json{}", said,
                     endpoint->body == BodyKind::JsonOrForm ? " (or the mesh as a multipart/form-data upload)" : ""));
      }
      admitted.body = BodyKind::Json;
      admitted.bodyLimit = kJsonBodyLimit;
      break;
  }
  if (head.contentLength && *head.contentLength > admitted.bodyLimit && admitted.body != BodyKind::None) {
    throw ApiError(
        413, fmt::format("the body is {} bytes; {} takes at most {}", *head.contentLength, said, admitted.bodyLimit));
  }
  return admitted;
}

std::optional<Caller> AccessGate::callerOverTcp(const RequestHead& head, const RequestTarget& target, Route route,
                                                std::string& refusal) {
  const std::string_view value = head.authorization;
  std::string secret;
  bool inAddress = false;
  if (value.size() > 7 && asciiLower(value.substr(0, 7)) == "bearer ") {
    secret = std::string(value.substr(7));
  } else if (route == Route::Events) {
    // A browser's event stream cannot send a header: its session in the
    // address, where a configured token is never taken (addresses end up in
    // histories and logs; a session ends, a token does not).
    secret = queryValue(target.query, "session");
    inAddress = true;
  }
  if (secret.empty()) {
    refusal = tokens_.empty()
                  ? "this listener needs a session: run `rotafab dashboard` on the daemon's machine for a login link"
                  : "this listener needs a token: send `Authorization: Bearer TOKEN` (rotafab --token T), or a "
                    "session from `rotafab dashboard`";
    return std::nullopt;
  }
  const auto now = Clock::now();
  if (const auto found = sessions_.find(secret); found != sessions_.end()) {
    if (now - found->second.second < kSessionLasts) {
      found->second.second = now;
      return Caller{found->second.first, true};
    }
    sessions_.erase(found);
  }
  if (!inAddress) {
    for (const TokenConfig& configured : tokens_) {
      if (tokenMatches(secret, configured.hash)) return Caller{configured.name, false};
    }
  }
  refusal = inAddress ? "the session in the address is not one this daemon knows (a session ends when the daemon "
                        "starts again; a token goes in the Authorization header): run `rotafab dashboard` for a new "
                        "link"
                      : "the token or session is not one this daemon knows (a session ends when the daemon starts "
                        "again): run `rotafab dashboard` for a new link";
  return std::nullopt;
}

void AccessGate::checkHost(const RequestHead& head) const {
  if (head.host.empty()) throw ApiError(400, "the request has no Host header (HTTP/1.1 needs one)");
  if (isLoopbackHost(head.host)) return;
  const std::string name = hostName(head.host);
  for (const std::string& origin : origins_) {
    if (hostName(origin) == name) return;
  }
  throw ApiError(421, fmt::format("Host: {}: this listener answers to this machine's loopback names only "
                                  "(127.0.0.1, localhost, [::1]); a page reached under another name is refused; "
                                  "behind a reverse proxy, list its address in the configuration's origins",
                                  std::string(head.host)));
}

void AccessGate::checkFraming(const RequestHead& head) {
  if (!head.repeated.empty()) {
    throw ApiError(400, fmt::format("the request has more than one {} header", std::string(head.repeated)));
  }
  if (head.transferEncoding.empty()) return;
  // Chunked alone: a coding the daemon does not know (or chunked under
  // another) would leave where the body ends to a guess.
  std::string coding = asciiLower(head.transferEncoding);
  std::erase_if(coding, [](char c) { return c == ' ' || c == '\t'; });
  if (coding != "chunked") {
    throw ApiError(501, fmt::format("Transfer-Encoding: {}: the daemon reads chunked bodies and bodies of a "
                                    "Content-Length only",
                                    shownText(head.transferEncoding, 60)));
  }
  if (head.contentLength) throw ApiError(400, "the request has both a Content-Length and a Transfer-Encoding");
}

void AccessGate::checkSameOrigin(const RequestHead& head) const {
  const std::string site = asciiLower(head.fetchSite);
  if (!site.empty() && site != "same-origin" && site != "none") {
    throw ApiError(403, fmt::format("a request from another site's page ({}) may not change anything here",
                                    std::string(head.fetchSite)));
  }
  if (head.origin.empty()) return;  // not a browser's (browsers send Origin with every POST)
  const std::string origin = asciiLower(head.origin);
  if (origin == "http://" + asciiLower(head.host)) return;
  if (std::find(origins_.begin(), origins_.end(), origin) != origins_.end()) return;
  throw ApiError(403, fmt::format("Origin: {}: a page of another origin may not change anything here (this "
                                  "listener's own is http://{}; behind a reverse proxy, list the page's address "
                                  "in the configuration's origins)",
                                  std::string(head.origin), std::string(head.host)));
}

std::string AccessGate::newLoginCode(const std::string& name) {
  const auto now = Clock::now();
  std::erase_if(loginCodes_, [&](const auto& entry) { return entry.second.second < now; });
  std::string code = randomSecret();
  loginCodes_[code] = {name, now + kLoginLinkLasts};
  return code;
}

std::optional<std::string> AccessGate::openSession(const std::string& code) {
  const auto found = loginCodes_.find(code);
  if (found == loginCodes_.end()) return std::nullopt;
  const auto [name, until] = found->second;
  loginCodes_.erase(found);
  const auto now = Clock::now();
  if (until < now) return std::nullopt;
  std::erase_if(sessions_, [&](const auto& entry) { return now - entry.second.second >= kSessionLasts; });
  std::string secret = randomSecret();
  sessions_[secret] = {name, now};
  return secret;
}

}  // namespace rotafab::service
