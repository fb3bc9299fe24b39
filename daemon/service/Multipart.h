#pragma once
// multipart/form-data (RFC 7578), as browsers and `curl -F` send a file
// with fields: the parts of a body, each with its name, its file name (for
// a file) and its bytes.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rotafab::service {

struct FormPart {
  std::string name;
  std::optional<std::string> fileName;
  std::string_view bytes;  // into the body
};

// The boundary of a Content-Type "multipart/form-data; boundary=...", or none.
std::optional<std::string> multipartBoundary(std::string_view contentType);

// The parts; throws std::invalid_argument saying what is malformed.
std::vector<FormPart> parseMultipart(std::string_view body, const std::string& boundary);

}  // namespace rotafab::service
