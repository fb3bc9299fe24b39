#include "jobs/SheetReader.h"

#include <fmt/format.h>

#include <charconv>
#include <fstream>
#include <optional>
#include <regex>
#include <stdexcept>

namespace rotafab::jobs {
namespace {

// One number at `at` in `text`, skipping spaces and commas before it.
bool number(std::string_view text, size_t& at, double& value) {
  while (at < text.size() && (text[at] == ' ' || text[at] == ',')) ++at;
  const auto [end, error] = std::from_chars(text.data() + at, text.data() + text.size(), value);
  if (error != std::errc()) return false;
  at = static_cast<size_t>(end - text.data());
  return true;
}

bool contains(const std::string& line, std::string_view tag) { return line.find(tag) != std::string::npos; }

}  // namespace

SheetDrawing readSheetSvg(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read it", file.string()));
  const auto fail = [&](int line, const std::string& what) {
    return std::invalid_argument(fmt::format("{}:{}: {}", file.string(), line, what));
  };
  static const std::regex svgTag(R"re(<svg [^>]*viewBox="0 0 ([0-9.]+) ([0-9.]+)")re");
  static const std::regex descTag(
      R"re(<desc>rotafab sheet (\d+) of (\d+); units: inches; bed [0-9.]+ x [0-9.]+ in, margin ([0-9.]+) in</desc>)re");
  static const std::regex titleTag(R"re(<title>(.*)</title>)re");
  static const std::regex groupTag(
      R"re(<g id="([a-z]+)" fill="none" stroke="#([0-9a-f]{2})([0-9a-f]{2})([0-9a-f]{2})")re");
  // A path is one line of any length: read without a regular expression,
  // whose matcher recurses per character.
  constexpr std::string_view pathStart = "<path d=\"", pathEnd = "\"/>";
  SheetDrawing sheet;
  bool sized = false, described = false;
  Operation group = Operation::Outline;
  bool inGroup = false;
  int depth = 0;  // groups open inside the operation's (a part's)
  std::string line;
  int lineNumber = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    std::smatch m;
    if (line.starts_with(pathStart) && line.ends_with(pathEnd)) {
      if (!inGroup) throw fail(lineNumber, "a path outside an operation's group");
      if (!sized) throw fail(lineNumber, "a path before the <svg> element's viewBox");
      const std::string_view d =
          std::string_view(line).substr(pathStart.size(), line.size() - pathStart.size() - pathEnd.size());
      DrawnPath path{group, {}, false};
      size_t at = 0;
      while (at < d.size()) {
        const char command = d[at];
        if (command == ' ') {
          ++at;
        } else if (command == 'Z' && path.points.size() >= 2 && !path.closed) {
          path.closed = true;
          ++at;
        } else if (!path.closed &&
                   ((command == 'M' && path.points.empty()) || (command == 'L' && !path.points.empty()))) {
          ++at;
          double x = 0, y = 0;
          if (!number(d, at, x) || !number(d, at, y)) {
            throw fail(lineNumber, fmt::format("path data: no coordinate pair at character {}", at + 1));
          }
          path.points.emplace_back(x, sheet.height - y);
        } else {
          throw fail(lineNumber, fmt::format("path data: '{}' at character {} (rotafab writes M, then L, then Z)",
                                             command, at + 1));
        }
      }
      if (path.points.size() < 2) throw fail(lineNumber, "a path of fewer than 2 points");
      sheet.paths.push_back(std::move(path));
      // (Each regular expression only where its tag is: most lines are none of these.)
    } else if (!sized && contains(line, "<svg ") && std::regex_search(line, m, svgTag)) {
      sheet.width = std::stod(m[1]), sheet.height = std::stod(m[2]);
      sized = true;
    } else if (contains(line, "<desc>") && std::regex_search(line, m, descTag)) {
      sheet.index = std::stoi(m[1]), sheet.sheetCount = std::stoi(m[2]), sheet.margin = std::stod(m[3]);
      described = true;
    } else if (contains(line, "<title>") && std::regex_search(line, m, titleTag)) {
      sheet.title = m[1];
    } else if (contains(line, "<g id=\"") && std::regex_search(line, m, groupTag)) {
      const auto named = profiles::operationNamed(m[1].str());
      if (!named) {
        throw fail(lineNumber, fmt::format("group \"{}\" is not an operation (cut, score, etch, outline)", m[1].str()));
      }
      group = *named, inGroup = true, depth = 0;
      sheet.colours[group] = {static_cast<uint8_t>(std::stoi(m[2], nullptr, 16)),
                              static_cast<uint8_t>(std::stoi(m[3], nullptr, 16)),
                              static_cast<uint8_t>(std::stoi(m[4], nullptr, 16))};
    } else if (inGroup && line.starts_with("<g ")) {
      ++depth;
    } else if (line == "</g>") {
      if (depth > 0)
        --depth;
      else
        inGroup = false;
    }
  }
  if (!sized) throw fail(lineNumber, "not a sheet of rotafab's: no <svg> element with a viewBox \"0 0 W H\"");
  if (!described) throw fail(lineNumber, "not a sheet of rotafab's: no <desc> with the sheet number and margin");
  try {
    checkDrawable(sheet);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(fmt::format("{}: {}", file.string(), error.what()));
  }
  return sheet;
}

}  // namespace rotafab::jobs
