#include "geometry/io/MeshReaders.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

namespace rotafab::geometry {
namespace {

// The whole token as a number (from_chars, plus an optional leading '+').
template <typename Number>
std::optional<Number> parseNumber(std::string_view token) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  Number value{};
  auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}
std::optional<double> parseReal(std::string_view token) { return parseNumber<double>(token); }
std::optional<long long> parseInteger(std::string_view token) { return parseNumber<long long>(token); }

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

std::vector<std::string_view> splitWords(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSpace(line[i])) ++i;
    size_t start = i;
    while (i < line.size() && !isSpace(line[i])) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Shortens a token for a message so that binary garbage cannot flood it.
std::string shownToken(std::string_view token) {
  std::string shown;
  for (char c : token.substr(0, 24)) shown += (static_cast<unsigned char>(c) >= 32 && c != 127) ? c : '?';
  return fmt::format("'{}{}'", shown, token.size() > 24 ? "..." : "");
}

// Walks the non-blank lines of a text, with '#' comments removed.
class CommentedLines {
 public:
  explicit CommentedLines(std::string_view text) : text_(text) {}

  // The words of the next line that has any, or nullopt at the end.
  std::optional<std::vector<std::string_view>> next() {
    while (position_ < text_.size()) {
      size_t end = text_.find('\n', position_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(position_, end - position_);
      position_ = end + 1;
      ++lineNumber_;
      if (size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      auto words = splitWords(line);
      if (!words.empty()) return words;
    }
    return std::nullopt;
  }
  [[nodiscard]] int lineNumber() const { return lineNumber_; }

 private:
  std::string_view text_;
  size_t position_ = 0;
  int lineNumber_ = 0;
};

[[noreturn]] void failAtLine(int line, const std::string& what) {
  throw InvalidMeshError(fmt::format("line {}: {}", line, what));
}

long long countFrom(std::string_view token, int line, const char* what) {
  auto value = parseInteger(token);
  if (!value || *value < 0)
    failAtLine(line, fmt::format("the {} count {} is not a non-negative integer", what, shownToken(token)));
  return *value;
}

void checkFinite(const Point3& p, long long vertex, int line) {
  if (!p.allFinite()) failAtLine(line, fmt::format("vertex {} has a non-finite coordinate {}", vertex, formatPoint(p)));
}

}  // namespace

PolygonMesh readOff(std::string_view text) {
  CommentedLines lines(text);
  auto header = lines.next();
  if (!header) throw InvalidMeshError("the file is empty");
  std::string_view keyword = (*header)[0];
  std::vector<std::string_view> counts;
  if (parseInteger(keyword)) {
    // Geomview's OFF spec makes the keyword optional: the file opens with the counts.
    counts = *header;
  } else {
    // Optional prefixes: ST (texture), C (colour), N (normal), 4 / n (dimension).
    if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") {
      failAtLine(lines.lineNumber(), fmt::format("expected the OFF header, found {}", shownToken(keyword)));
    }
    if (keyword.find('4') != std::string_view::npos || keyword.find('n') != std::string_view::npos) {
      failAtLine(lines.lineNumber(),
                 fmt::format("{} (4D or nD) files are not supported; 3D OFF is", shownToken(keyword)));
    }
    counts.assign(header->begin() + 1, header->end());
    if (!counts.empty() && counts[0] == "BINARY")
      failAtLine(lines.lineNumber(), "binary OFF is not supported; write it as text");
    if (counts.empty()) {
      auto next = lines.next();
      if (!next) throw InvalidMeshError("truncated: the file ends before the vertex and face counts");
      counts = *next;
    }
  }
  const int countsLine = lines.lineNumber();
  if (counts.size() < 2) failAtLine(countsLine, "expected the vertex and face counts");
  const long long vertexCount = countFrom(counts[0], countsLine, "vertex");
  const long long faceCount = countFrom(counts[1], countsLine, "face");
  // Every vertex needs at least 6 bytes ("0 0 0\n"), every face 8; a larger
  // count is a truncated or corrupt file, and must not make us allocate.
  if (vertexCount > static_cast<long long>(text.size()) || faceCount > static_cast<long long>(text.size())) {
    failAtLine(countsLine, fmt::format("the header states {} vertices and {} faces, more than a {}-byte file can hold",
                                       vertexCount, faceCount, text.size()));
  }

  PolygonMesh mesh;
  mesh.positions.reserve(vertexCount);
  for (long long v = 0; v < vertexCount; ++v) {
    auto words = lines.next();
    if (!words) {
      throw InvalidMeshError(
          fmt::format("truncated: the header states {} vertices, the file ends after {}", vertexCount, v));
    }
    if (words->size() < 3) failAtLine(lines.lineNumber(), fmt::format("vertex {} has fewer than 3 coordinates", v));
    Point3 p;
    for (int axis = 0; axis < 3; ++axis) {
      auto value = parseReal((*words)[axis]);
      if (!value)
        failAtLine(lines.lineNumber(), fmt::format("vertex {}: {} is not a number", v, shownToken((*words)[axis])));
      p[axis] = *value;
    }
    checkFinite(p, v, lines.lineNumber());
    mesh.positions.push_back(p);
  }
  mesh.faces.reserve(faceCount);
  for (long long f = 0; f < faceCount; ++f) {
    auto words = lines.next();
    if (!words) {
      throw InvalidMeshError(
          fmt::format("truncated: the header states {} faces, the file ends after {}", faceCount, f));
    }
    const int line = lines.lineNumber();
    auto size = parseInteger((*words)[0]);
    if (!size || *size < 1)
      failAtLine(line, fmt::format("face {}: {} is not a corner count", f, shownToken((*words)[0])));
    if (static_cast<long long>(words->size()) - 1 < *size) {
      failAtLine(line, fmt::format("face {} states {} corners but lists {}", f, *size, words->size() - 1));
    }
    std::vector<int> face;
    face.reserve(*size);
    for (long long i = 1; i <= *size; ++i) {
      auto index = parseInteger((*words)[i]);
      if (!index) failAtLine(line, fmt::format("face {}: {} is not a vertex index", f, shownToken((*words)[i])));
      if (*index < 0 || *index >= vertexCount) {
        failAtLine(line, fmt::format("face {} refers to vertex {}, but the file has {} vertices (0 to {})", f, *index,
                                     vertexCount, vertexCount - 1));
      }
      face.push_back(static_cast<int>(*index));
    }
    mesh.faces.push_back(std::move(face));
  }
  return mesh;
}

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

std::optional<PlyType> plyTypeNamed(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, PlyType>, 16> names{{
      {"char", PlyType::Int8},
      {"int8", PlyType::Int8},
      {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},
      {"short", PlyType::Int16},
      {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16},
      {"uint16", PlyType::UInt16},
      {"int", PlyType::Int32},
      {"int32", PlyType::Int32},
      {"uint", PlyType::UInt32},
      {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32},
      {"float32", PlyType::Float32},
      {"double", PlyType::Float64},
      {"float64", PlyType::Float64},
  }};
  for (auto [n, t] : names)
    if (n == name) return t;
  return std::nullopt;
}

size_t plyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool isList = false;
  PlyType countType = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { Ascii, BinaryLittleEndian, BinaryBigEndian };

// Reads the values of a PLY body one at a time, ASCII or binary, with bounds
// checks; a short body is reported as truncation of the element being read.
class PlyValues {
 public:
  PlyValues(std::string_view body, PlyFormat format, int firstLine) : body_(body), format_(format), line_(firstLine) {}

  std::optional<double> next(PlyType type) {
    if (format_ == PlyFormat::Ascii) {
      while (position_ < body_.size() && isSpace(body_[position_])) {
        if (body_[position_] == '\n') ++line_;
        ++position_;
      }
      if (position_ >= body_.size()) return std::nullopt;
      size_t start = position_;
      while (position_ < body_.size() && !isSpace(body_[position_])) ++position_;
      std::string_view token = body_.substr(start, position_ - start);
      auto value = parseReal(token);
      if (!value) failAtLine(line_, fmt::format("{} is not a number", shownToken(token)));
      return value;
    }
    const size_t size = plyTypeSize(type);
    if (body_.size() - position_ < size) return std::nullopt;
    std::array<unsigned char, 8> raw{};
    std::memcpy(raw.data(), body_.data() + position_, size);
    position_ += size;
    const bool fileIsLittle = format_ == PlyFormat::BinaryLittleEndian;
    if (fileIsLittle != (std::endian::native == std::endian::little)) std::reverse(raw.begin(), raw.begin() + size);
    switch (type) {
      case PlyType::Int8:
        return static_cast<double>(std::bit_cast<int8_t>(raw[0]));
      case PlyType::UInt8:
        return static_cast<double>(raw[0]);
      case PlyType::Int16:
        return load<int16_t>(raw);
      case PlyType::UInt16:
        return load<uint16_t>(raw);
      case PlyType::Int32:
        return load<int32_t>(raw);
      case PlyType::UInt32:
        return load<uint32_t>(raw);
      case PlyType::Float32:
        return load<float>(raw);
      case PlyType::Float64:
        return load<double>(raw);
    }
    return std::nullopt;
  }

  [[nodiscard]] size_t remainingBytes() const { return body_.size() - position_; }
  // "line N: " in an ASCII body (the line of the value read last), "" in a binary one.
  [[nodiscard]] std::string where() const {
    return format_ == PlyFormat::Ascii ? fmt::format("line {}: ", line_) : std::string();
  }

 private:
  template <typename T>
  static double load(const std::array<unsigned char, 8>& raw) {
    T value;
    std::memcpy(&value, raw.data(), sizeof(T));
    return static_cast<double>(value);
  }

  std::string_view body_;
  PlyFormat format_;
  size_t position_ = 0;
  int line_;
};

// What a PLY header declares, and where its body starts.
struct PlyHeader {
  PlyFormat format = PlyFormat::Ascii;
  std::vector<PlyElement> elements;
  size_t bodyStart = 0;  // the byte after the end_header line
};

PlyFormat plyFormatOf(const std::vector<std::string_view>& w, int line) {
  if (w.size() < 2) failAtLine(line, "the format line names no format");
  if (w[1] == "ascii") return PlyFormat::Ascii;
  if (w[1] == "binary_little_endian") return PlyFormat::BinaryLittleEndian;
  if (w[1] == "binary_big_endian") return PlyFormat::BinaryBigEndian;
  failAtLine(line, fmt::format("unknown format {}", shownToken(w[1])));
}

PlyProperty plyPropertyFrom(const std::vector<std::string_view>& w, int line) {
  if (w.size() >= 5 && w[1] == "list") {
    auto countType = plyTypeNamed(w[2]);
    auto type = plyTypeNamed(w[3]);
    if (!countType) failAtLine(line, fmt::format("unknown list count type {}", shownToken(w[2])));
    if (!type) failAtLine(line, fmt::format("unknown list value type {}", shownToken(w[3])));
    return {std::string(w[4]), *type, true, *countType};
  }
  if (w.size() >= 3 && w[1] != "list") {
    auto type = plyTypeNamed(w[1]);
    if (!type) failAtLine(line, fmt::format("unknown property type {}", shownToken(w[1])));
    return {std::string(w[2]), *type, false, PlyType::UInt8};
  }
  failAtLine(line, "a property needs a type and a name");
}

PlyHeader readPlyHeader(std::string_view bytes) {
  if (bytes.empty()) throw InvalidMeshError("the file is empty");
  size_t headerEnd = bytes.find("\nend_header");  // at the start of a line, not inside a comment
  if (headerEnd != std::string_view::npos) ++headerEnd;
  if (bytes.substr(0, 3) != "ply") throw InvalidMeshError("line 1: expected 'ply'");
  if (headerEnd == std::string_view::npos) throw InvalidMeshError("truncated: the header has no end_header line");
  PlyHeader result;
  result.bodyStart = bytes.find('\n', headerEnd);
  result.bodyStart = result.bodyStart == std::string_view::npos ? bytes.size() : result.bodyStart + 1;

  CommentedLines header(bytes.substr(0, headerEnd + 10));
  std::optional<PlyFormat> format;
  std::vector<PlyElement>& elements = result.elements;
  while (auto words = header.next()) {
    const int line = header.lineNumber();
    const auto& w = *words;
    if (w[0] == "ply" || w[0] == "comment" || w[0] == "obj_info" || w[0] == "end_header") continue;
    if (w[0] == "format") {
      format = plyFormatOf(w, line);
    } else if (w[0] == "element") {
      if (w.size() < 3) failAtLine(line, "an element needs a name and a count");
      elements.push_back({std::string(w[1]), countFrom(w[2], line, "element"), {}});
    } else if (w[0] == "property") {
      if (elements.empty()) failAtLine(line, "a property before any element");
      elements.back().properties.push_back(plyPropertyFrom(w, line));
    }
    // Anything else is a free-form line some writers add (Blender: "Created by
    // Blender3D ..."); like a comment, it is ignored.
  }
  if (!format) throw InvalidMeshError("the header has no format line");
  result.format = *format;
  return result;
}

// The positions of the vertex element's x, y and z among its properties.
std::array<int, 3> plyCoordinateProperties(const PlyElement& vertexElement) {
  std::array<int, 3> coordinateProperty{-1, -1, -1};
  for (size_t p = 0; p < vertexElement.properties.size(); ++p) {
    const auto& name = vertexElement.properties[p].name;
    if (name.size() == 1 && name[0] >= 'x' && name[0] <= 'z' && !vertexElement.properties[p].isList) {
      coordinateProperty[name[0] - 'x'] = static_cast<int>(p);
    }
  }
  if (coordinateProperty[0] < 0 || coordinateProperty[1] < 0 || coordinateProperty[2] < 0) {
    throw InvalidMeshError("the vertex element lacks an x, y or z property");
  }
  return coordinateProperty;
}

// The position of the face element's vertex index list among its properties.
int plyFaceList(const PlyElement& faceElement) {
  int faceList = -1;
  for (size_t p = 0; p < faceElement.properties.size(); ++p) {
    const auto& property = faceElement.properties[p];
    if (property.isList && (property.name == "vertex_indices" || property.name == "vertex_index")) {
      faceList = static_cast<int>(p);
    }
  }
  if (faceList < 0) throw InvalidMeshError("the face element has no vertex_indices list");
  return faceList;
}

InvalidMeshError plyTruncated(const PlyElement& element, long long read) {
  return InvalidMeshError(fmt::format("truncated: the header states {} {} elements, the file ends after {}",
                                      element.count, shownToken(element.name), read));
}

// One list property of instance `i`; its values go to `indices` where it is the face's vertex list, else nowhere.
void readPlyList(PlyValues& values, const PlyElement& element, const PlyProperty& property, long long i,
                 std::vector<int>* indices) {
  auto size = values.next(property.countType);
  if (!size) throw plyTruncated(element, i);
  if (*size < 0 || *size != std::floor(*size) || *size > 1e6) {
    throw InvalidMeshError(
        fmt::format("{}{} {}: {} is not a list length", values.where(), shownToken(element.name), i, *size));
  }
  for (long long k = 0; k < static_cast<long long>(*size); ++k) {
    auto value = values.next(property.type);
    if (!value) throw plyTruncated(element, i);
    if (indices) {
      if (*value != std::floor(*value) || *value < 0 || *value > 2147483647.0) {
        throw InvalidMeshError(fmt::format("{}face {}: {} is not a vertex index", values.where(), i, *value));
      }
      indices->push_back(static_cast<int>(*value));
    }
  }
}

// Every instance of one element: the vertex element's positions and the face
// element's faces go to `mesh` (with where each face was read, in `faceWhere`);
// any other element is read past.
void readPlyElement(PlyValues& values, const PlyElement& element, bool isVertex,
                    const std::array<int, 3>& coordinateProperty, PolygonMesh& mesh,
                    std::vector<std::string>& faceWhere) {
  const bool isFace = element.name == "face";
  const int faceList = isFace ? plyFaceList(element) : -1;
  // Each instance takes at least one byte (binary) or two (ascii); a count
  // larger than the rest of the file is a truncated or corrupt file.
  if (element.count > static_cast<long long>(values.remainingBytes())) {
    throw InvalidMeshError(
        fmt::format("truncated: the header states {} {} elements, more than the {} bytes left can hold", element.count,
                    shownToken(element.name), values.remainingBytes()));
  }
  for (long long i = 0; i < element.count; ++i) {
    Point3 p = Point3::Zero();
    std::vector<int> face;
    for (size_t pi = 0; pi < element.properties.size(); ++pi) {
      const auto& property = element.properties[pi];
      if (property.isList) {
        readPlyList(values, element, property, i, static_cast<int>(pi) == faceList ? &face : nullptr);
      } else {
        auto value = values.next(property.type);
        if (!value) throw plyTruncated(element, i);
        if (isVertex) {
          for (int axis = 0; axis < 3; ++axis)
            if (coordinateProperty[axis] == static_cast<int>(pi)) p[axis] = *value;
        }
      }
    }
    if (isVertex) {
      if (!p.allFinite()) {
        throw InvalidMeshError(
            fmt::format("{}vertex {} has a non-finite coordinate {}", values.where(), i, formatPoint(p)));
      }
      mesh.positions.push_back(p);
    }
    if (isFace) {
      mesh.faces.push_back(std::move(face));
      faceWhere.push_back(values.where());
    }
  }
}

// Checked once every element is read: the face element may come before the vertex element.
void checkPlyFaceIndices(const PolygonMesh& mesh, const std::vector<std::string>& faceWhere, long long vertexCount) {
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int index : mesh.faces[f]) {
      if (index >= vertexCount) {
        throw InvalidMeshError(fmt::format("{}face {} refers to vertex {}, but the file has {} vertices (0 to {})",
                                           faceWhere[f], f, index, vertexCount, vertexCount - 1));
      }
    }
  }
}

}  // namespace

PolygonMesh readPly(std::string_view bytes) {
  const PlyHeader header = readPlyHeader(bytes);
  const PlyElement* vertexElement = nullptr;
  for (const auto& e : header.elements)
    if (e.name == "vertex") vertexElement = &e;
  if (!vertexElement) throw InvalidMeshError("the header declares no vertex element");
  const std::array<int, 3> coordinateProperty = plyCoordinateProperties(*vertexElement);

  const int bodyLine = 1 + static_cast<int>(std::count(bytes.begin(), bytes.begin() + header.bodyStart, '\n'));
  PlyValues values(bytes.substr(header.bodyStart), header.format, bodyLine);
  PolygonMesh mesh;
  std::vector<std::string> faceWhere;  // where each face was read, for the index check
  long long vertexCount = 0;
  for (const auto& element : header.elements) {
    const bool isVertex = &element == vertexElement;
    readPlyElement(values, element, isVertex, coordinateProperty, mesh, faceWhere);
    if (isVertex) vertexCount = element.count;
  }
  checkPlyFaceIndices(mesh, faceWhere, vertexCount);
  return mesh;
}

}  // namespace rotafab::geometry
