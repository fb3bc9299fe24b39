#include "geometry/io/MeshFileChecks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>

namespace rotafab::geometry {
namespace {

std::string_view trimmedStart(std::string_view text) {
  const size_t start = text.find_first_not_of(" \t\r\n");
  return start == std::string_view::npos ? std::string_view() : text.substr(start);
}

bool startsWithKeyword(std::string_view text, std::string_view keyword) {
  return text.size() > keyword.size() && text.substr(0, keyword.size()) == keyword &&
         std::isspace(static_cast<unsigned char>(text[keyword.size()]));
}

// Calls `visit(lineNumber, line)` for each line, 1-based; stops when it returns false.
template <typename Visit>
void forEachLine(std::string_view bytes, Visit visit) {
  size_t position = 0;
  long long number = 0;
  while (position < bytes.size()) {
    size_t end = bytes.find('\n', position);
    if (end == std::string_view::npos) end = bytes.size();
    std::string_view line = bytes.substr(position, end - position);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    position = end + 1;
    if (!visit(++number, line)) return;
  }
}

// The first word of a line after leading blanks, and the rest.
std::pair<std::string_view, std::string_view> firstWord(std::string_view line) {
  const size_t start = line.find_first_not_of(" \t");
  if (start == std::string_view::npos) return {};
  line.remove_prefix(start);
  const size_t end = line.find_first_of(" \t");
  if (end == std::string_view::npos) return {line, {}};
  return {line.substr(0, end), line.substr(end)};
}

bool looksLikeObj(std::string_view bytes) {
  bool vertices = false, faces = false;
  int lines = 0;
  forEachLine(bytes.substr(0, 1 << 16), [&](long long, std::string_view line) {
    const auto word = firstWord(line).first;
    vertices = vertices || word == "v";
    faces = faces || word == "f";
    return ++lines < 2000 && !(vertices && faces);
  });
  return vertices;
}

// True when the first kilobytes hold no NUL and few control characters.
bool isText(std::string_view bytes) {
  const std::string_view head = bytes.substr(0, 4096);
  size_t control = 0;
  for (unsigned char c : head) {
    if (c == 0) return false;
    if (c < 32 && c != '\n' && c != '\r' && c != '\t' && c != '\f') ++control;
  }
  return control * 100 <= head.size();
}

std::string suffixFor(const std::string& format) {
  if (format == "OBJ") return "obj";
  if (format == "OFF") return "off";
  if (format == "PLY") return "ply";
  if (format == "glTF") return "gltf";
  if (format == "binary glTF") return "glb";
  if (format == "text STL") return "stl";
  return "";
}

std::string upper(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::toupper(c); });
  return text;
}

std::string formatName(const std::string& extension) {
  if (extension == "gltf") return "glTF";
  if (extension == "glb") return "binary glTF";
  return upper(extension);
}

std::string lowercaseFirst(std::string text) {
  if (text.size() > 1 && std::isupper(static_cast<unsigned char>(text[0])) &&
      !std::isupper(static_cast<unsigned char>(text[1]))) {
    text[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(text[0])));
  }
  while (!text.empty() && (text.back() == '.' || std::isspace(static_cast<unsigned char>(text.back())))) {
    text.pop_back();
  }
  return text;
}

bool contains(std::string_view text, std::string_view part) { return text.find(part) != std::string_view::npos; }

}  // namespace

std::string recognisedContent(std::string_view bytes) {
  if (bytes.starts_with("glTF")) return "binary glTF";
  if (bytes.starts_with("\xFE\xFF") || bytes.starts_with("\xFF\xFE")) return "UTF-16 text";
  if (!isText(bytes)) return "binary";
  std::string_view text = trimmedStart(bytes);
  if (text.starts_with("\xEF\xBB\xBF")) text = trimmedStart(text.substr(3));
  if (startsWithKeyword(text, "ply")) return "PLY";
  const std::string_view first = firstWord(text.substr(0, text.find('\n'))).first;
  if (first.size() >= 3 && first.size() <= 8 && first.ends_with("OFF")) return "OFF";
  if (startsWithKeyword(text, "solid")) return "text STL";
  if (text.starts_with("{")) return "glTF";
  if (looksLikeObj(bytes)) return "OBJ";
  return "";
}

std::optional<std::string> contentMismatch(std::string_view bytes, const std::string& extension) {
  // Assimp 5.2 reads no face of a UTF-16 OBJ, and our OFF and PLY readers read bytes.
  if ((extension == "obj" || extension == "off" || extension == "ply" || extension == "stl") &&
      recognisedContent(bytes) == "UTF-16 text") {
    return fmt::format("the file is UTF-16 text; {} is read as UTF-8 or ASCII: save it again as UTF-8",
                       formatName(extension));
  }
  const auto renameHint = [](const std::string& seen) {
    const std::string suffix = suffixFor(seen);
    return suffix.empty() ? std::string() : fmt::format(": it looks like {}; rename it to .{}", seen, suffix);
  };
  if (extension == "stl") {
    // A binary STL is 84 bytes of header and count, then 50 per triangle; its
    // 80-byte header may say anything, even "solid".
    uint32_t triangles = 0;
    if (bytes.size() >= 84) std::memcpy(&triangles, bytes.data() + 80, 4);
    if (bytes.size() >= 84 && bytes.size() == 84 + 50ull * triangles) return std::nullopt;
    const std::string seen = recognisedContent(bytes);
    if (seen == "text STL" || seen == "binary") return std::nullopt;
    return fmt::format("the file is text, not STL (a text STL starts with 'solid'){}", renameHint(seen));
  }
  if (extension == "obj") {
    const std::string seen = recognisedContent(bytes);
    if (seen == "binary") return std::string("the file is binary, not OBJ (an OBJ file is text)");
    if (!seen.empty() && seen != "OBJ") return fmt::format("the file is not OBJ{}", renameHint(seen));
    return std::nullopt;
  }
  if (extension == "off" || extension == "ply") {
    const std::string seen = recognisedContent(bytes);
    if (seen.empty() || seen == "binary" || seen == formatName(extension)) return std::nullopt;
    return fmt::format("the file is not {}{}", formatName(extension), renameHint(seen));
  }
  return std::nullopt;
}

std::optional<std::string> objFaceIndexProblem(std::string_view bytes) {
  long long total = 0;
  forEachLine(bytes, [&](long long, std::string_view line) {
    if (firstWord(line).first == "v") ++total;
    return true;
  });
  std::optional<std::string> problem;
  long long before = 0;
  forEachLine(bytes, [&](long long number, std::string_view line) {
    auto [word, rest] = firstWord(line);
    if (word == "v") ++before;
    if (word != "f" && word != "l" && word != "p") return true;
    const std::string_view what = word == "f" ? "face" : word == "l" ? "line" : "point";
    if (const size_t comment = rest.find('#'); comment != std::string_view::npos) rest = rest.substr(0, comment);
    while (true) {
      auto [corner, after] = firstWord(rest);
      if (corner.empty()) break;
      rest = after;
      const std::string_view vertex = corner.substr(0, corner.find('/'));
      long long index = 0;
      const auto [end, error] = std::from_chars(vertex.data(), vertex.data() + vertex.size(), index);
      if (error != std::errc() || end != vertex.data() + vertex.size() || index == 0) {
        problem = fmt::format("line {}: the {}'s corner '{}' is not a vertex number (1 and up, or -1 and down)", number,
                              what, corner);
        return false;
      }
      if (index > total) {
        problem = fmt::format("line {}: the {} refers to vertex {}, but the file has {} vert{}", number, what, index,
                              total, total == 1 ? "ex" : "ices");
        return false;
      }
      if (index < 0 && -index > before) {
        problem = fmt::format("line {}: the {} refers to vertex {} (counted back), but only {} vert{} come before it",
                              number, what, index, before, before == 1 ? "ex" : "ices");
        return false;
      }
    }
    return true;
  });
  return problem;
}

std::string explainReaderFailure(std::string_view message, std::string_view bytes, const std::string& extension) {
  const std::string format = formatName(extension);
  // The scene came back without a single polygon (Assimp's validation and
  // readers say so in terms of their data structure).
  if (contains(message, "is a LINE") || contains(message, "is a POINT")) {
    return "the file holds no polygon faces, only points and lines";
  }
  if (contains(message, "contains no faces") || contains(message, "contains no vertices") ||
      contains(message, "mNumMeshes is 0") || contains(message, "No scene") || contains(message, "too small") ||
      contains(message, "no meshes")) {
    return "the file holds no polygon faces";
  }
  if (extension == "obj" && (contains(message, "index out of range") || contains(message, "Invalid face index"))) {
    if (auto problem = objFaceIndexProblem(bytes)) return *problem;
    return "a face refers to a vertex the file does not have";
  }
  if (contains(message, "No suitable reader") || contains(message, "determine STL storage")) {
    const std::string seen = recognisedContent(bytes);
    if (seen == "binary glTF" && bytes.size() >= 8 && bytes[4] != 2) {
      return fmt::format("the file is binary glTF version {}; only glTF 2.0 is read: export it again as glTF 2.0",
                         static_cast<int>(static_cast<unsigned char>(bytes[4])));
    }
    const std::string suffix = suffixFor(seen);
    if (!suffix.empty() && suffix != extension) {
      return fmt::format("the file is not {}: it looks like {}; rename it to .{}", format, seen, suffix);
    }
    if (extension.empty()) return "the file's name has no extension, which names its format (.obj, .stl, .ply, ...)";
    return fmt::format("the file is not {}, or is malformed: its contents are not what a .{} file holds", format,
                       extension);
  }
  // Anything else Assimp says is about the file; said as the reader's finding,
  // on one line, without the file's path (the error starts with it already).
  // Assimp's readers start some messages with their own tag ("OBJ: ").
  std::string_view rest = message;
  if (const size_t colon = rest.find(": "); colon != std::string_view::npos && colon > 0 && colon <= 6 &&
                                            std::all_of(rest.begin(), rest.begin() + colon, [](unsigned char c) {
                                              return std::isupper(c) || std::isdigit(c);
                                            })) {
    rest.remove_prefix(colon + 2);
  }
  std::string said = lowercaseFirst(std::string(rest));
  if (said.empty()) said = "it could not be read";
  return fmt::format("the {} file is malformed: {}", format, said);
}

}  // namespace rotafab::geometry
