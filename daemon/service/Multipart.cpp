#include "daemon/service/Multipart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "daemon/service/ApiInput.h"

namespace rotafab::service {
namespace {

// A parameter of a header value: name="value" or name=value.
std::optional<std::string> parameter(std::string_view header, std::string_view name) {
  const std::string lowered = asciiLower(header);
  size_t at = 0;
  while ((at = lowered.find(name, at)) != std::string::npos) {
    const bool starts = at == 0 || lowered[at - 1] == ';' || lowered[at - 1] == ' ' || lowered[at - 1] == '\t';
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
    value = value.substr(0, value.find(';'));
    while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.remove_suffix(1);
    return std::string(value);
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> multipartBoundary(std::string_view contentType) {
  if (!asciiLower(contentType).starts_with("multipart/form-data")) return std::nullopt;
  auto boundary = parameter(contentType, "boundary");
  if (!boundary || boundary->empty() || boundary->size() > 70) return std::nullopt;
  return boundary;
}

MultipartReader::MultipartReader(const std::string& boundary, Parts& parts)
    : first_("--" + boundary), delimiter_("\r\n--" + boundary), parts_(parts) {}

void MultipartReader::feed(std::string_view bytes) {
  if (state_ == State::Epilogue) return;  // what follows the closing delimiter is nobody's
  held_.append(bytes);
  while (step()) {
  }
}

void MultipartReader::finish() const {
  switch (state_) {
    case State::Epilogue:
      return;
    case State::Preamble:
      throw std::invalid_argument("the body has no part (no boundary line)");
    case State::Body:
      throw std::invalid_argument("the body ends inside a part (no closing boundary)");
    default:
      throw std::invalid_argument("the body ends inside a part's header");
  }
}

bool MultipartReader::step() {
  switch (state_) {
    case State::Preamble: {
      const size_t at = held_.find(first_);
      if (at == std::string::npos) {
        // Anything before the first delimiter is a preamble, read past.
        if (held_.size() >= first_.size()) held_.erase(0, held_.size() - (first_.size() - 1));
        return false;
      }
      held_.erase(0, at + first_.size());
      state_ = State::AfterDelimiter;
      return true;
    }
    case State::AfterDelimiter:
      if (held_.size() < 2) return false;
      if (held_.starts_with("--")) {
        state_ = State::Epilogue;
        held_.clear();
        return false;
      }
      if (!held_.starts_with("\r\n")) throw std::invalid_argument("a boundary line does not end in CRLF");
      held_.erase(0, 2);
      state_ = State::Headers;
      return true;
    case State::Headers: {
      size_t end = 0, skip = 2;  // a part without header fields
      if (!held_.starts_with("\r\n")) {
        end = held_.find("\r\n\r\n"), skip = 4;
        if (end == std::string::npos && held_.size() <= kLongestPartHeader + 4) return false;
      }
      if (end == std::string::npos || end > kLongestPartHeader) {
        throw std::invalid_argument(fmt::format("a part's header is longer than {} KiB", kLongestPartHeader / 1024));
      }
      if (++partsSeen_ > kMostParts) throw std::invalid_argument(fmt::format("more than {} parts", kMostParts));
      readHeaders(std::string_view(held_).substr(0, end));
      held_.erase(0, end + skip);
      state_ = State::Body;
      return true;
    }
    case State::Body: {
      const size_t at = held_.find(delimiter_);
      if (at != std::string::npos) {
        if (at > 0) parts_.bytes(std::string_view(held_).substr(0, at));
        parts_.end();
        held_.erase(0, at + delimiter_.size());
        state_ = State::AfterDelimiter;
        return true;
      }
      // All but what could be the start of a delimiter goes to the part now.
      if (held_.size() >= delimiter_.size()) {
        const size_t safe = held_.size() - (delimiter_.size() - 1);
        parts_.bytes(std::string_view(held_).substr(0, safe));
        held_.erase(0, safe);
      }
      return false;
    }
    case State::Epilogue:
      held_.clear();
      return false;
  }
  return false;
}

void MultipartReader::readHeaders(std::string_view headers) {
  FormPartHead head;
  bool named = false;
  while (!headers.empty()) {
    const size_t end = headers.find("\r\n");
    const std::string_view line = headers.substr(0, end);
    headers = end == std::string_view::npos ? std::string_view() : headers.substr(end + 2);
    const size_t colon = line.find(':');
    if (colon == std::string_view::npos) throw std::invalid_argument("a part's header has no colon");
    if (asciiLower(line.substr(0, colon)) != "content-disposition") continue;
    const std::string_view value = line.substr(colon + 1);
    if (auto name = parameter(value, "name")) head.name = *name, named = true;
    head.fileName = parameter(value, "filename");
  }
  if (!named) throw std::invalid_argument("a part has no Content-Disposition name");
  parts_.begin(head);
}

std::vector<FormPart> parseMultipart(std::string_view body, const std::string& boundary) {
  struct Collected : MultipartReader::Parts {
    std::vector<FormPart> parts;
    void begin(const FormPartHead& head) override { parts.push_back({head.name, head.fileName, ""}); }
    void bytes(std::string_view bytes) override { parts.back().bytes.append(bytes); }
    void end() override {}
  } collected;
  MultipartReader reader(boundary, collected);
  reader.feed(body);
  reader.finish();
  return std::move(collected.parts);
}

}  // namespace rotafab::service
