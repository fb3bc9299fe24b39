#pragma once
// A request's target as the daemon reads it: one spelling for all the
// spellings of a path (RFC 3986, 6.2.2: percent-decoding; 5.2.4: dot
// segments removed), so that the gate that decides who may ask and the
// router that answers read the same path. "//api/jobs", "/%61pi/jobs",
// "/./api/jobs" and "/x/../api/jobs" are all "/api/jobs"; what cannot be
// read one way only is refused.

#include <string>
#include <string_view>
#include <vector>

namespace rotafab::service {

struct RequestTarget {
  // The path's segments: percent-decoded, "." and empty segments dropped,
  // each ".." taking away the one before it.
  std::vector<std::string> parts;
  std::string query;  // what follows '?', as sent (queryValue decodes a value)

  // "/" and the parts joined by "/": the path as the gate and the router read it.
  [[nodiscard]] std::string path() const;
};

// Throws ApiError(400) saying what is wrong: a target that is not a path
// (an absolute URI, "*"), a fragment, a malformed percent escape, an encoded
// '/' or '\', a NUL or another control character, ".." above the root, or
// more than 64 segments.
RequestTarget parseTarget(std::string_view target);

// The value of `key` in a query ("a=1&key=v"), percent-decoded ('+' is a
// space); empty when it is not there or cannot be decoded.
std::string queryValue(std::string_view query, std::string_view key);

}  // namespace rotafab::service
