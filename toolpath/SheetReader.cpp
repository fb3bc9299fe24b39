#include "toolpath/SheetReader.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
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

bool contains(std::string_view line, std::string_view tag) { return line.find(tag) != std::string_view::npos; }

// The path data rotafab writes: "M x y", then absolute "L x y" or relative
// "l dx dy" pairs (a command's letter may be left out before its next pair),
// and "Z" to close; or a circle, "M x y" at its rightmost point and two half
// arcs "a r r 0 1 0 -2r 0 a r r 0 1 0 2r 0 Z". Sheet y is up, the SVG's down.
template <class Fail>
DrawnPath pathOf(std::string_view d, double height, const Fail& fail) {
  DrawnPath path;
  size_t at = 0;
  const auto skipSpaces = [&] {
    while (at < d.size() && (d[at] == ' ' || d[at] == ',')) ++at;
  };
  const auto pair = [&](double& x, double& y) {
    if (!number(d, at, x) || !number(d, at, y)) throw fail(at, "no coordinate pair");
  };
  const auto startsNumber = [&] {
    skipSpaces();
    return at < d.size() && (d[at] == '-' || d[at] == '+' || d[at] == '.' || (d[at] >= '0' && d[at] <= '9'));
  };
  double x = 0, y = 0;
  char command = 0;
  while (true) {
    skipSpaces();
    if (at >= d.size()) break;
    if (!startsNumber()) {
      command = d[at];
      const bool allowed = path.closed                                          ? false
                           : command == 'M'                                     ? path.points.empty()
                           : command == 'L' || command == 'l' || command == 'Z' ? !path.points.empty()
                           : command == 'a'                                     ? path.points.size() == 1
                                                                                : false;
      if (!allowed)
        throw fail(at, fmt::format("'{}' (rotafab writes M, then L or l, then Z; or a circle's M a a Z)", d[at]));
      ++at;
      if (command == 'Z') {
        if (path.points.size() < 2) throw fail(at - 1, "Z after fewer than 2 points");
        path.closed = true;
      }
      if (command != 'a') continue;
      // A circle: both half arcs at once.
      double r[2][2], flags[2][3], across[2][2];
      for (int half = 0; half < 2; ++half) {
        if (half == 1) {
          skipSpaces();
          if (at >= d.size() || d[at] != 'a') throw fail(at, "a circle's second half arc missing");
          ++at;
        }
        pair(r[half][0], r[half][1]);
        for (double& flag : flags[half])
          if (!number(d, at, flag)) throw fail(at, "no arc flags");
        pair(across[half][0], across[half][1]);
      }
      const double radius = r[0][0];
      const auto near = [&](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); };
      if (!(radius > 0 && near(r[0][1], radius) && near(r[1][0], radius) && near(r[1][1], radius) &&
            near(across[0][0], -2 * radius) && near(across[1][0], 2 * radius) && across[0][1] == 0 &&
            across[1][1] == 0 && flags[0][0] == 0 && flags[1][0] == 0 && flags[0][1] == 1 && flags[1][1] == 1 &&
            flags[0][2] == 0 && flags[1][2] == 0))
        throw fail(at, "arcs that are not a circle's two halves (rotafab writes circles only)");
      skipSpaces();
      if (at >= d.size() || d[at] != 'Z') throw fail(at, "a circle not closed by Z");
      ++at;
      path = circlePath(path.operation, Circle{{x - radius, height - y}, radius});
      skipSpaces();
      if (at < d.size()) throw fail(at, "more after a circle");
      break;
    }
    if (command != 'M' && command != 'L' && command != 'l') throw fail(at, "a number without a command");
    double px = 0, py = 0;
    pair(px, py);
    if (command == 'l') {
      x += px, y += py;
    } else {
      x = px, y = py;
    }
    path.points.emplace_back(x, height - y);
    if (command == 'M') command = 'L';  // SVG: pairs after M's first are lines
  }
  return path;
}

}  // namespace

SheetDrawing readSheetSvg(const std::filesystem::path& file) {
  // Read whole, then taken a line at a time: the daemon reads every sheet of a folder submitted to it.
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read it", file.string()));
  std::string text;
  in.seekg(0, std::ios::end);
  text.resize(static_cast<size_t>(std::max<std::streamoff>(0, in.tellg())));
  in.seekg(0);
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
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
  int lineNumber = 0;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + start, end - start);
    start = end + 1;
    ++lineNumber;
    std::match_results<std::string_view::const_iterator> m;
    if (line.starts_with(pathStart) && line.ends_with(pathEnd)) {
      if (!inGroup) throw fail(lineNumber, "a path outside an operation's group");
      if (!sized) throw fail(lineNumber, "a path before the <svg> element's viewBox");
      const std::string_view d = line.substr(pathStart.size(), line.size() - pathStart.size() - pathEnd.size());
      DrawnPath path = pathOf(d, sheet.height, [&](size_t at, const std::string& what) {
        return fail(lineNumber, fmt::format("path data: {} at character {}", what, at + 1));
      });
      path.operation = group;
      if (path.points.size() < 2) throw fail(lineNumber, "a path of fewer than 2 points");
      sheet.paths.push_back(std::move(path));
      // (Each regular expression only where its tag is: most lines are none of these.)
    } else if (!sized && contains(line, "<svg ") && std::regex_search(line.begin(), line.end(), m, svgTag)) {
      sheet.width = std::stod(m[1]), sheet.height = std::stod(m[2]);
      sized = true;
    } else if (contains(line, "<desc>") && std::regex_search(line.begin(), line.end(), m, descTag)) {
      sheet.index = std::stoi(m[1]), sheet.sheetCount = std::stoi(m[2]), sheet.margin = std::stod(m[3]);
      described = true;
    } else if (contains(line, "<title>") && std::regex_search(line.begin(), line.end(), m, titleTag)) {
      sheet.title = m[1];
    } else if (contains(line, "<g id=\"") && contains(line, "stroke=\"#") &&
               std::regex_search(line.begin(), line.end(), m, groupTag)) {
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
