#include "daemon/service/RequestTarget.h"

#include <fmt/format.h>

#include <optional>

#include "daemon/service/ApiError.h"

namespace rotafab::service {
namespace {

constexpr size_t kMostSegments = 64;

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The bytes `text` percent-encodes; none when an escape is malformed.
std::optional<std::string> percentDecoded(std::string_view text, bool plusIsSpace) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '%') {
      if (i + 2 >= text.size()) return std::nullopt;
      const int high = hexValue(text[i + 1]), low = hexValue(text[i + 2]);
      if (high < 0 || low < 0) return std::nullopt;
      out += static_cast<char>(high * 16 + low);
      i += 2;
    } else if (plusIsSpace && text[i] == '+') {
      out += ' ';
    } else {
      out += text[i];
    }
  }
  return out;
}

}  // namespace

std::string RequestTarget::path() const {
  std::string out;
  for (const std::string& part : parts) out += "/" + part;
  return out.empty() ? "/" : out;
}

RequestTarget parseTarget(std::string_view target) {
  const auto refuse = [&](std::string_view why) -> ApiError {
    return ApiError(400, fmt::format("the request's path {}", why));
  };
  // Only the origin form (RFC 9112, 3.2.1): what a client sends to a server that is not a proxy.
  if (target.empty() || target.front() != '/') throw refuse("must begin with /");
  if (target.find('#') != std::string_view::npos) throw refuse("has a fragment (#), which is not sent to a server");
  RequestTarget read;
  const size_t mark = target.find('?');
  if (mark != std::string_view::npos) read.query = std::string(target.substr(mark + 1));
  std::string_view path = target.substr(0, mark);
  size_t segments = 0;
  while (!path.empty()) {
    const size_t slash = path.find('/');
    const std::string_view raw = path.substr(0, slash);
    path = slash == std::string_view::npos ? std::string_view() : path.substr(slash + 1);
    if (++segments > kMostSegments) throw refuse(fmt::format("has more than {} segments", kMostSegments));
    const auto decoded = percentDecoded(raw, false);
    if (!decoded) throw refuse("has a malformed percent escape (% and two hexadecimal digits)");
    for (const char c : *decoded) {
      const auto byte = static_cast<unsigned char>(c);
      // An encoded slash would be one segment here and two to a proxy in
      // front; a backslash is a slash to some; control characters are nobody's.
      if (c == '/' || c == '\\') throw refuse("has an encoded / or \\ in a segment");
      if (byte < 0x20 || byte == 0x7f) throw refuse("has a control character");
    }
    if (decoded->empty() || *decoded == ".") continue;
    if (*decoded == "..") {
      if (read.parts.empty()) throw refuse("goes above the root (..)");
      read.parts.pop_back();
      continue;
    }
    read.parts.push_back(*decoded);
  }
  return read;
}

std::string queryValue(std::string_view query, std::string_view key) {
  while (!query.empty()) {
    const size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const size_t equals = pair.find('=');
    if (equals != std::string_view::npos && percentDecoded(pair.substr(0, equals), true) == std::string(key)) {
      return percentDecoded(pair.substr(equals + 1), true).value_or("");
    }
    if (amp == std::string_view::npos) break;
    query = query.substr(amp + 1);
  }
  return "";
}

}  // namespace rotafab::service
