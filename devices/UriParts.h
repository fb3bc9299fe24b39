#pragma once
// Pieces of device URIs that several drivers read alike.

#include <charconv>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace rotafab::devices {

// `text` as a number, all of it (nothing when anything else is there).
template <typename Number>
std::optional<Number> wholeNumber(const std::string& text, int base = 10) {
  Number value{};
  const char* last = text.data() + text.size();
  std::from_chars_result result;
  if constexpr (std::is_floating_point_v<Number>) {
    result = std::from_chars(text.data(), last, value);
  } else {
    result = std::from_chars(text.data(), last, value, base);
  }
  if (text.empty() || result.ec != std::errc() || result.ptr != last) return std::nullopt;
  return value;
}

// "1a86" as a USB vendor or product id.
inline std::optional<uint16_t> hexId(const std::string& text) {
  const auto value = wholeNumber<unsigned>(text, 16);
  if (text.size() != 4 || !value) return std::nullopt;
  return static_cast<uint16_t>(*value);
}

// "path?query" as the path and the query (empty when there is none).
inline std::pair<std::string, std::string> splitQuery(const std::string& rest) {
  const auto query = rest.find('?');
  if (query == std::string::npos) return {rest, ""};
  return {rest.substr(0, query), rest.substr(query + 1)};
}

// One option of a URI's query: "speed=50" is key "speed", value "50".
struct QueryOption {
  std::string text, key, value;
};
// The options of "a=1&b=2", in order.
inline std::vector<QueryOption> queryOptions(std::string query) {
  std::vector<QueryOption> options;
  while (!query.empty()) {
    const size_t end = query.find('&');
    std::string option = query.substr(0, end);
    query = end == std::string::npos ? "" : query.substr(end + 1);
    const size_t equals = option.find('=');
    std::string key = option.substr(0, equals), value = equals == std::string::npos ? "" : option.substr(equals + 1);
    options.push_back({std::move(option), std::move(key), std::move(value)});
  }
  return options;
}

// What is wrong with a device URI, with examples of good ones.
inline std::invalid_argument uriError(const std::string& uri, const std::string& what) {
  return std::invalid_argument(
      uri + ": " + what +
      " (e.g. grbl:///dev/ttyUSB0?baud=115200, grbl+tcp://192.168.4.1:23, ruida://192.168.1.100, sim:grbl)");
}

}  // namespace rotafab::devices
