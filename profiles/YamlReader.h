#pragma once
// Reading a YAML file that people write (profiles, the daemon's
// configuration) and refusing what is wrong in one line,
// "FILE:LINE:COL: key: what is wrong", pointing at the key or value at fault.

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>
#include <cctype>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/LengthUnit.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::profiles {

// Walks one YAML document and refuses what is wrong with file:line:col.
class YamlReader {
 public:
  explicit YamlReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
    const YAML::Mark mark = at.Mark();
    const int line = mark.line >= 0 ? mark.line + 1 : 1, column = mark.column >= 0 ? mark.column + 1 : 1;
    throw ProfileError(fmt::format("{}:{}:{}: {}: {}", file_.string(), line, column, key, what));
  }

  // The document, which must be a map (`what` names it in the refusal:
  // "profile", "expected a map of keys (kind, name, ...)"). An empty file is
  // an empty map when `emptyIsMap`.
  YAML::Node load(const std::string& what = "profile",
                  const std::string& expected = "expected a map of keys (kind, name, ...)",
                  bool emptyIsMap = false) const {
    try {
      YAML::Node root = YAML::LoadFile(file_.string());
      if (emptyIsMap && root.IsNull()) return YAML::Node(YAML::NodeType::Map);
      if (!root.IsMap()) fail(root, what, expected);
      return root;
    } catch (const YAML::BadFile&) {
      throw ProfileError(fmt::format("{}: cannot read the file", file_.string()));
    } catch (const YAML::ParserException& error) {
      throw ProfileError(
          fmt::format("{}:{}:{}: syntax: {}", file_.string(), error.mark.line + 1, error.mark.column + 1, error.msg));
    }
  }

  // Refuses unknown and repeated keys, and missing required ones; returns the
  // key node of each key present, for messages.
  std::map<std::string, YAML::Node> keys(const YAML::Node& map, const std::string& path,
                                         const std::vector<std::string>& allowed,
                                         const std::vector<std::string>& required) const {
    if (!map.IsMap()) fail(map, path, "expected a map");
    std::map<std::string, YAML::Node> present;
    for (const auto& entry : map) {
      const std::string key = entry.first.as<std::string>("");
      const std::string where = path.empty() ? key : path + "." + key;
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        fail(entry.first, where, fmt::format("unknown key (expected one of: {})", fmt::join(allowed, ", ")));
      }
      if (!present.emplace(key, entry.first).second) fail(entry.first, where, "given twice");
    }
    for (const auto& key : required) {
      if (!present.contains(key)) fail(map, path.empty() ? key : path + "." + key, "missing");
    }
    return present;
  }

  std::string text(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected text");
    return node.Scalar();
  }

  // The unit lengths are shown to people in (`units: mm`): mm or in.
  core::LengthUnit shownUnit(const YAML::Node& node, const std::string& key) const {
    const std::string name = text(node, key);
    const auto unit = core::LengthUnit::named(name);
    if (!unit) fail(node, key, fmt::format("{}: expected mm or in", name));
    return *unit;
  }

  double number(const YAML::Node& node, const std::string& key, double low, double high) const {
    double value = 0;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
      fail(node, key, fmt::format("expected a number, found '{}'", node.IsScalar() ? node.Scalar() : "a list or map"));
    }
    if (value < low || value > high)
      fail(node, key, fmt::format("must be between {} and {}, not {}", low, high, value));
    return value;
  }

  int integer(const YAML::Node& node, const std::string& key, int low, int high) const {
    int value = 0;
    if (!node.IsScalar() || !YAML::convert<int>::decode(node, value)) {
      fail(node, key,
           fmt::format("expected a whole number, found '{}'", node.IsScalar() ? node.Scalar() : "a list or map"));
    }
    if (value < low || value > high)
      fail(node, key, fmt::format("must be between {} and {}, not {}", low, high, value));
    return value;
  }

  // Whether a length is written without its unit.
  static bool isBareNumber(std::string text) {
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return !text.empty() && (std::isdigit(static_cast<unsigned char>(text.back())) != 0 || text.back() == '.');
  }

  bool boolean(const YAML::Node& node, const std::string& key) const {
    bool value = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
      fail(node, key,
           fmt::format("expected on/off (true/false), found '{}'", node.IsScalar() ? node.Scalar() : "a list or map"));
    }
    return value;
  }

  // A length: 0.25in, 6.35mm, 0.635cm, 2ft, 1.2m or a bare number of
  // inches; must exceed `low`. A bare number above `mostBareInches` is
  // refused: more likely millimetres than inches ("bed.width: 400 without a
  // unit").
  double length(const YAML::Node& node, const std::string& key, double low, bool inclusive,
                double mostBareInches) const {
    const auto value = node.IsScalar() ? parseLength(node.Scalar()) : std::nullopt;
    if (!value) {
      fail(node, key,
           fmt::format("expected a length such as 0.25in, 6.35mm or 0.635cm, found '{}'",
                       node.IsScalar() ? node.Scalar() : "a list or map"));
    }
    if (std::string text = node.Scalar(); *value > mostBareInches && isBareNumber(text)) {
      fail(node, key,
           fmt::format("{} without a unit, which would be {} inches; write {}mm or {}in", text, text, text, text));
    }
    if (inclusive ? *value < low : *value <= low) {
      fail(node, key, fmt::format("must be {} {}in, not {}", inclusive ? "at least" : "more than", low, node.Scalar()));
    }
    return *value;
  }

  // A speed (`order` 1: 100mm/s, 6000mm/min, 4in/s) or an acceleration
  // (`order` 2: 500mm/s2, 500mm/s^2), in inches and seconds; positive.
  double rate(const YAML::Node& node, const std::string& key, int order) const {
    const std::string text = node.IsScalar() ? node.Scalar() : "";
    const char* example = order == 1 ? "100mm/s, 6000mm/min or 4in/s" : "500mm/s2 or 20in/s2";
    const size_t slash = text.find('/');
    const std::string length = text.substr(0, slash), per = slash == std::string::npos ? "" : text.substr(slash + 1);
    // The unit written, not a bare number: "100/s" is too easily meant in mm.
    const bool unitWritten = length.ends_with("in") || length.ends_with("mm") || length.ends_with("cm");
    const double inches = unitWritten ? parseLength(length).value_or(0.0) : 0.0;
    double seconds = 0;
    if (order == 1) seconds = per == "s" ? 1 : per == "min" ? 60 : 0;
    if (order == 2) seconds = per == "s2" || per == "s^2" ? 1 : 0;
    if (!(inches > 0) || seconds == 0) {
      fail(node, key,
           fmt::format("expected {} such as {}, found '{}'", order == 1 ? "a speed" : "an acceleration", example,
                       node.IsScalar() ? text : "a list or map"));
    }
    return inches / (order == 1 ? seconds : seconds * seconds);
  }

  Rgb rgb(const YAML::Node& node, const std::string& key) const {
    if (node.IsScalar() && node.Scalar().size() == 7 && node.Scalar()[0] == '#') {
      char* end = nullptr;
      const long value = std::strtol(node.Scalar().c_str() + 1, &end, 16);
      if (end == node.Scalar().c_str() + 7) {
        return {static_cast<uint8_t>(value >> 16), static_cast<uint8_t>(value >> 8 & 255),
                static_cast<uint8_t>(value & 255)};
      }
    }
    if (node.IsSequence() && node.size() == 3) {
      return {static_cast<uint8_t>(integer(node[0], key + "[0]", 0, 255)),
              static_cast<uint8_t>(integer(node[1], key + "[1]", 0, 255)),
              static_cast<uint8_t>(integer(node[2], key + "[2]", 0, 255))};
    }
    fail(node, key, "expected a colour as [red, green, blue] from 0 to 255, or \"#rrggbb\"");
  }

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

}  // namespace rotafab::profiles
