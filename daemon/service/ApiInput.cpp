#include "daemon/service/ApiInput.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <iterator>
#include <optional>

#include "daemon/service/ApiError.h"

namespace rotafab::service {
using nlohmann::json;

namespace {

ApiError outOfRange(const NumberField& field) {
  return ApiError(400, fmt::format("{}: expected a whole number from {} to {}", field.name, field.least, field.most));
}

// The code point of the UTF-8 sequence at `text[at]` and its length; none when it is not one.
std::optional<std::pair<char32_t, size_t>> codePointAt(std::string_view text, size_t at) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(at);
  if (lead < 0x80) return std::pair<char32_t, size_t>{lead, 1};
  size_t length = 0;
  char32_t point = 0;
  if ((lead & 0xe0) == 0xc0) {
    length = 2, point = lead & 0x1f;
  } else if ((lead & 0xf0) == 0xe0) {
    length = 3, point = lead & 0x0f;
  } else if ((lead & 0xf8) == 0xf0) {
    length = 4, point = lead & 0x07;
  } else {
    return std::nullopt;
  }
  if (at + length > text.size()) return std::nullopt;
  for (size_t i = 1; i < length; ++i) {
    if ((byte(at + i) & 0xc0) != 0x80) return std::nullopt;
    point = (point << 6) | (byte(at + i) & 0x3f);
  }
  // Overlong forms, surrogates and what lies beyond Unicode are not UTF-8.
  static constexpr char32_t kLeast[] = {0, 0, 0x80, 0x800, 0x10000};
  if (point < kLeast[length] || point > 0x10ffff || (point >= 0xd800 && point <= 0xdfff)) return std::nullopt;
  return std::pair<char32_t, size_t>{point, length};
}

// C0 and C1 controls and DEL; the line and paragraph separators; every
// format character of Unicode 15 (general category Cf: the bidirectional
// marks, embeddings, overrides and isolates, which make "gpj.obj" read as
// another name and a log line say what it does not; the zero-width ones;
// the tag characters, invisible in most fonts); and the fillers shown as nothing.
bool unshown(char32_t point) {
  struct Range {
    char32_t first, last;
  };
  static constexpr Range kUnshown[] = {
      {0x0000, 0x001f},   {0x007f, 0x009f},   {0x00ad, 0x00ad},   {0x034f, 0x034f},   {0x0600, 0x0605},
      {0x061c, 0x061c},   {0x06dd, 0x06dd},   {0x070f, 0x070f},   {0x0890, 0x0891},   {0x08e2, 0x08e2},
      {0x115f, 0x1160},   {0x17b4, 0x17b5},   {0x180e, 0x180e},   {0x200b, 0x200f},   {0x2028, 0x202e},
      {0x2060, 0x2064},   {0x2066, 0x206f},   {0x3164, 0x3164},   {0xfeff, 0xfeff},   {0xffa0, 0xffa0},
      {0xfff9, 0xfffb},   {0x110bd, 0x110bd}, {0x110cd, 0x110cd}, {0x13430, 0x1343f}, {0x1bca0, 0x1bca3},
      {0x1d173, 0x1d17a}, {0xe0000, 0xe007f},
  };
  return std::any_of(std::begin(kUnshown), std::end(kUnshown),
                     [point](const Range& range) { return point >= range.first && point <= range.last; });
}

// The longest start of `text` of at most `most` bytes that ends between two code points.
std::string_view cutAt(std::string_view text, size_t most) {
  if (text.size() <= most) return text;
  size_t end = most;
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xc0) == 0x80) --end;
  return text.substr(0, end);
}

}  // namespace

std::string asciiLower(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return out;
}

int64_t wholeNumber(const json& value, const NumberField& field) {
  if (value.is_number_unsigned()) {
    const auto number = value.get<uint64_t>();
    if (number > static_cast<uint64_t>(field.most) || static_cast<int64_t>(number) < field.least) {
      throw outOfRange(field);
    }
    return static_cast<int64_t>(number);
  }
  if (value.is_number_integer()) {
    const auto number = value.get<int64_t>();
    if (number < field.least || number > field.most) throw outOfRange(field);
    return number;
  }
  if (value.is_string()) {
    if (const auto number = wholeNumberIn(value.get<std::string>(), field)) return *number;
  }
  throw outOfRange(field);
}

std::optional<int64_t> wholeNumberIn(std::string_view text, const NumberField& field) {
  int64_t number = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  if (number < field.least || number > field.most) return std::nullopt;
  return number;
}

std::string checkedText(const json& value, std::string_view field, size_t most) {
  if (!value.is_string()) throw ApiError(400, fmt::format("{}: expected text", field));
  const std::string& text = value.get_ref<const std::string&>();
  if (text.size() > most) throw ApiError(400, fmt::format("{}: longer than {} bytes", field, most));
  for (size_t at = 0; at < text.size();) {
    const auto point = codePointAt(text, at);
    if (!point) throw ApiError(400, fmt::format("{}: not UTF-8 text", field));
    if (unshown(point->first)) {
      throw ApiError(400, fmt::format("{}: has a control or invisible character (U+{:04X})", field,
                                      static_cast<uint32_t>(point->first)));
    }
    at += point->second;
  }
  return text;
}

std::string shownText(std::string_view text, size_t most) {
  std::string shown;
  for (size_t at = 0; at < text.size();) {
    const auto point = codePointAt(text, at);
    if (!point) {
      ++at;  // a byte that is not UTF-8: dropped
      continue;
    }
    if (!unshown(point->first)) shown.append(text.substr(at, point->second));
    at += point->second;
  }
  return std::string(cutAt(shown, most));
}

std::string cleanFileName(std::string_view sent) {
  // Its last component: some browsers send a whole Windows path.
  if (const size_t slash = sent.find_last_of("/\\"); slash != std::string_view::npos) sent = sent.substr(slash + 1);
  std::string name = shownText(sent, sent.size());
  while (!name.empty() && (name.back() == ' ' || name.back() == '.')) name.pop_back();
  while (!name.empty() && name.front() == ' ') name.erase(name.begin());
  if (name.size() > kLongestFileName) {
    // Shortened in its stem: the extension says what reads the file.
    const size_t dot = name.rfind('.');
    const std::string extension = dot != std::string::npos && name.size() - dot <= 12 ? name.substr(dot) : "";
    name = std::string(cutAt(name, kLongestFileName - extension.size())) + extension;
  }
  if (name == "." || name == "..") return "";
  return name;
}

std::string withoutDaemonPaths(std::string message, const std::vector<std::string>& folders) {
  for (const std::string& folder : folders) {
    if (folder.empty() || folder == "/") continue;
    for (size_t at = message.find(folder); at != std::string::npos; at = message.find(folder, at + 1)) {
      // The path runs to the first character a path in a message is not followed by.
      size_t end = at + folder.size();
      while (end < message.size() && std::string_view(" :;,\"'()\n").find(message[end]) == std::string_view::npos)
        ++end;
      std::string path = message.substr(at, end - at);
      while (path.size() > 1 && path.back() == '/') path.pop_back();
      const size_t slash = path.rfind('/');
      const std::string name = path.size() == folder.size() || slash == std::string::npos
                                   ? std::string("the daemon's folder")
                                   : path.substr(slash + 1);
      message.replace(at, end - at, name);
    }
  }
  return message;
}

json checkedActionArguments(std::string_view action, const json& body) {
  if (!body.is_object()) throw ApiError(400, "the body must be a JSON object");
  json checked = json::object();
  const auto takes = [&](std::initializer_list<std::string_view> fields) {
    for (const auto& [key, value] : body.items()) {
      if (std::find(fields.begin(), fields.end(), key) == fields.end()) {
        std::string names;
        for (std::string_view field : fields) names += (names.empty() ? "" : ", ") + std::string(field);
        throw ApiError(400, fmt::format("{} takes {}; not \"{}\"", action, names.empty() ? "no fields" : names,
                                        cleanFileName(key)));
      }
    }
  };
  if (action == "resume") {
    takes({kFromSheetField.name, kFromStrokeField.name});
    if (body.contains("from_sheet")) checked["from_sheet"] = wholeNumber(body["from_sheet"], kFromSheetField);
    if (body.contains("from_stroke")) checked["from_stroke"] = wholeNumber(body["from_stroke"], kFromStrokeField);
  } else if (action == "frame") {
    takes({kSheetField.name});
    if (body.contains("sheet")) checked["sheet"] = wholeNumber(body["sheet"], kSheetField);
  } else if (action == "move") {
    takes({kBeforeField.name, kPriorityField.name, "device"});
    if (body.contains("device")) checked["device"] = checkedText(body["device"], "device", 64);
    if (body.contains("before")) checked["before"] = wholeNumber(body["before"], kBeforeField);
    if (body.contains("priority")) checked["priority"] = wholeNumber(body["priority"], kPriorityField);
  } else {
    takes({});
  }
  return checked;
}

}  // namespace rotafab::service
