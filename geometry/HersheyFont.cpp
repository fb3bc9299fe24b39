#include "geometry/HersheyFont.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "core/ProgramFolders.h"

namespace rotafab::geometry {
namespace {

constexpr int kFirstCharacter = 32;  // the first record is the space
constexpr int kLastPrintable = 126;  // '~'; the record after it stands for DEL
constexpr int kCapitalTop = -12;     // Hershey's Roman fonts, font units, y down
constexpr int kBaseline = 9;

// `text` with anything unprintable written as \xNN, for messages.
std::string printable(std::string_view text) {
  std::string out;
  for (char c : text) {
    const auto code = static_cast<unsigned char>(c);
    if (code >= 32 && code < 127 && c != '"' && c != '\\')
      out += c;
    else if (c == '"' || c == '\\')
      out += fmt::format("\\{}", c);
    else
      out += fmt::format("\\x{:02x}", code);
  }
  return out;
}

}  // namespace

HersheyFont HersheyFont::load(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot open the Hershey font", file.string()));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(std::move(line));
  }

  HersheyFont font;
  size_t index = 0;
  while (index < lines.size()) {
    const size_t firstLine = index;
    std::string record = lines[index++];
    if (record.find_first_not_of(' ') == std::string::npos) continue;  // a blank line between records
    auto bad = [&](const std::string& what) {
      return std::runtime_error(fmt::format("{}:{}: {}", file.string(), firstLine + 1, what));
    };
    if (record.size() < 8) throw bad("a glyph record needs a 5-column number and a 3-column count");
    const std::string countField = record.substr(5, 3);
    const size_t digits = countField.find_first_not_of(' ');
    if (digits == std::string::npos || countField.find_first_not_of("0123456789", digits) != std::string::npos)
      throw bad(fmt::format("the count \"{}\" is not a number", countField));
    const int pairs = std::stoi(countField.substr(digits));
    if (pairs < 1) throw bad(fmt::format("the count {} leaves no room for the glyph's bounds", pairs));
    const size_t needed = 8 + 2 * static_cast<size_t>(pairs);
    while (record.size() < needed && index < lines.size()) record += lines[index++];  // a wrapped record
    if (record.size() < needed)
      throw bad(fmt::format("the glyph announces {} coordinate pairs but the file ends after {}", pairs,
                            (record.size() - 8) / 2));
    if (record.find_first_not_of(' ', needed) != std::string::npos)
      throw bad(fmt::format("text after the {} coordinate pairs the glyph announces", pairs));

    Glyph glyph;
    glyph.left = record[8] - 'R';
    glyph.right = record[9] - 'R';
    if (glyph.right < glyph.left) throw bad("the right bound lies left of the left bound");
    std::vector<Eigen::Vector2i> stroke;
    auto endStroke = [&] {
      // A single point is a pen-down without movement: nothing for a laser.
      if (stroke.size() >= 2) glyph.strokes.push_back(std::move(stroke));
      stroke.clear();
    };
    for (size_t at = 10; at < needed; at += 2) {
      const char x = record[at], y = record[at + 1];
      if (x == ' ' && y == 'R') {
        endStroke();
        continue;
      }
      if (x < '!' || x > '~' || y < '!' || y > '~')
        throw bad(fmt::format("coordinate pair {} (\"{}\") is not two printable characters", (at - 8) / 2,
                              printable(record.substr(at, 2))));
      stroke.emplace_back(x - 'R', y - 'R');
    }
    endStroke();
    font.glyphs_.push_back(std::move(glyph));
  }
  if (font.glyphs_.empty()) throw std::runtime_error(fmt::format("{}: no glyphs in the Hershey font", file.string()));
  return font;
}

const HersheyFont& HersheyFont::simplex() {
  static const HersheyFont font = [] {
    const auto installed = core::installedDataFolder() / "fonts" / "rowmans.jhf";
    std::error_code missing;
    return load(std::filesystem::exists(installed, missing)
                    ? installed
                    : std::filesystem::path(kDefaultFontFolder) / "rowmans.jhf");
  }();
  return font;
}

double HersheyFont::unitsToInches(double height) {
  if (!std::isfinite(height) || height <= 0)
    throw std::invalid_argument(fmt::format("text height {} is not a positive length", height));
  return height / (kBaseline - kCapitalTop);
}

const HersheyFont::Glyph& HersheyFont::glyphFor(std::string_view text, size_t position) const {
  const auto code = static_cast<unsigned char>(text[position]);
  if (code < kFirstCharacter || code > kLastPrintable || static_cast<size_t>(code - kFirstCharacter) >= glyphs_.size())
    throw std::invalid_argument(fmt::format(
        "cannot set \"{}\" in a Hershey font: character {} (code {}) at position {} has no glyph; only printable "
        "ASCII (' ' to '~') can be etched",
        printable(text), printable(text.substr(position, 1)), code, position + 1));
  return glyphs_[code - kFirstCharacter];
}

std::vector<Polyline> HersheyFont::strokes(std::string_view text, Point2 origin, double height,
                                           double angleRadians) const {
  const double unit = unitsToInches(height);
  if (!std::isfinite(angleRadians) || !origin.allFinite())
    throw std::invalid_argument("text origin and angle must be finite numbers");
  const Eigen::Vector2d along(std::cos(angleRadians), std::sin(angleRadians));
  const Eigen::Vector2d up(-along.y(), along.x());

  // Sized exactly: a large weave keeps a million of these.
  size_t count = 0;
  for (size_t i = 0; i < text.size(); ++i) count += glyphFor(text, i).strokes.size();
  std::vector<Polyline> out;
  out.reserve(count);
  double pen = 0;  // font units along the baseline
  for (size_t i = 0; i < text.size(); ++i) {
    const Glyph& glyph = glyphFor(text, i);
    for (const auto& stroke : glyph.strokes) {
      Polyline line;
      line.reserve(stroke.size());
      for (const Eigen::Vector2i& p : stroke) {
        const double x = (pen + p.x() - glyph.left) * unit;
        const double y = (kBaseline - p.y()) * unit;
        line.push_back(origin + x * along + y * up);
      }
      out.push_back(std::move(line));
    }
    pen += glyph.right - glyph.left;
  }
  return out;
}

double HersheyFont::advance(std::string_view text, double height) const {
  const double unit = unitsToInches(height);
  int width = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const Glyph& glyph = glyphFor(text, i);
    width += glyph.right - glyph.left;
  }
  return width * unit;
}

bool readsDifferentlyUpsideDown(std::string_view label) {
  if (label.empty()) return false;
  std::string upsideDown;
  for (auto c = label.rbegin(); c != label.rend(); ++c) {
    switch (*c) {
      case '0':
      case '1':
      case '8':
        upsideDown += *c;
        break;
      case '6':
        upsideDown += '9';
        break;
      case '9':
        upsideDown += '6';
        break;
      default:
        return false;  // upside down this is no number: nothing to confuse it with
    }
  }
  return upsideDown != label;
}

std::string labelText(std::string_view label) {
  std::string text(label);
  if (readsDifferentlyUpsideDown(label)) text += '.';
  return text;
}

std::vector<Polyline> labelStrokes(const HersheyFont& font, std::string_view label, Point2 origin, double height,
                                   double angleRadians) {
  return font.strokes(labelText(label), origin, height, angleRadians);
}

}  // namespace rotafab::geometry
