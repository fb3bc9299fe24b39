#include "daemon/service/Multipart.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace rotafab::service {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}

// A parameter of a header value: name="value" or name=value.
std::optional<std::string> parameter(std::string_view header, std::string_view name) {
  const std::string lowered = lower(header);
  size_t at = 0;
  while ((at = lowered.find(name, at)) != std::string::npos) {
    const bool starts = at == 0 || lowered[at - 1] == ';' || lowered[at - 1] == ' ';
    const size_t equals = at + name.size();
    if (!starts || equals >= header.size() || header[equals] != '=') {
      at = equals;
      continue;
    }
    std::string_view value = header.substr(equals + 1);
    if (!value.empty() && value[0] == '"') {
      const size_t close = value.find('"', 1);
      if (close == std::string_view::npos) return std::nullopt;
      return std::string(value.substr(1, close - 1));
    }
    return std::string(value.substr(0, value.find(';')));
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> multipartBoundary(std::string_view contentType) {
  if (!lower(contentType).starts_with("multipart/form-data")) return std::nullopt;
  auto boundary = parameter(contentType, "boundary");
  if (!boundary || boundary->empty() || boundary->size() > 200) return std::nullopt;
  return boundary;
}

std::vector<FormPart> parseMultipart(std::string_view body, const std::string& boundary) {
  const std::string delimiter = "--" + boundary;
  std::vector<FormPart> parts;
  size_t at = body.find(delimiter);
  if (at == std::string_view::npos) throw std::invalid_argument("the body has no part (no boundary line)");
  for (;;) {
    at += delimiter.size();
    if (body.substr(at, 2) == "--") return parts;  // the closing delimiter
    if (body.substr(at, 2) != "\r\n") throw std::invalid_argument("a boundary line does not end in CRLF");
    at += 2;
    const size_t headersEnd = body.find("\r\n\r\n", at);
    if (headersEnd == std::string_view::npos) throw std::invalid_argument("a part's headers do not end");
    FormPart part;
    bool named = false;
    std::string_view headers = body.substr(at, headersEnd - at);
    while (!headers.empty()) {
      const size_t end = headers.find("\r\n");
      const std::string_view line = headers.substr(0, end);
      headers = end == std::string_view::npos ? std::string_view() : headers.substr(end + 2);
      const size_t colon = line.find(':');
      if (colon == std::string_view::npos) throw std::invalid_argument("a part's header has no colon");
      if (lower(line.substr(0, colon)) != "content-disposition") continue;
      const std::string_view value = line.substr(colon + 1);
      if (auto name = parameter(value, "name")) part.name = *name, named = true;
      part.fileName = parameter(value, "filename");
    }
    if (!named) throw std::invalid_argument("a part has no Content-Disposition name");
    const size_t bytesStart = headersEnd + 4;
    const size_t next = body.find("\r\n" + delimiter, bytesStart);
    if (next == std::string_view::npos)
      throw std::invalid_argument("the body ends inside a part (no closing boundary)");
    part.bytes = body.substr(bytesStart, next - bytesStart);
    parts.push_back(std::move(part));
    at = next + 2;
  }
}

}  // namespace rotafab::service
