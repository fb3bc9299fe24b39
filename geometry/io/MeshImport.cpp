#include "geometry/io/MeshImport.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>
#include <unordered_map>

#include "core/ChildProcess.h"
#include "core/ProgramFolders.h"
#include "geometry/io/MeshFileChecks.h"
#include "geometry/io/MeshReaders.h"
#include "geometry/io/MeshWire.h"

namespace rotafab::geometry {
namespace {

std::string lowercase(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return lower;
}

std::string firstLine(const char* text) {
  std::string line = text ? text : "";
  if (size_t end = line.find('\n'); end != std::string::npos) line.resize(end);
  return line.empty() ? "the file could not be read" : line;
}

// The program that reads with Assimp (geometry/io/MeshReaderHost.cpp).
constexpr const char* kMeshReader = "rotafab-read-mesh";

// Assimp 5.2's OBJ reader fills a 16 MB buffer for every file, however
// small: 4096 page faults, 50 of the 72 ms a 1k-face OBJ took to read here.
// Allowed transparent huge pages (glibc's malloc then asks for them), 8
// faults: 24 ms. Where the system does not give them, nothing changes.
constexpr const char* kLargePages = "GLIBC_TUNABLES=glibc.malloc.hugetlb=1";

// Assimp in a program of its own (core/ChildProcess.h): Debian's Assimp 5.2
// aborts on some malformed files (its assertions are on) and may crash or
// hang on others; any of that becomes one clear error here instead of taking
// rotafab, or a daemon with other people's jobs in it, down.
PolygonMesh readWithAssimpHelper(std::string_view bytes, const std::string& extension,
                                 const std::filesystem::path* path, const core::Cancellation* cancellation) {
  // Generous, and in proportion to the file: Assimp reads 200k faces of OBJ
  // (11 MB) in about 0.15 s, yet it loops on some malformed files, and a
  // user should not wait minutes to hear that a small file is broken.
  const auto timeout = std::chrono::seconds(5 + 4 * (bytes.size() / 1'000'000));
  // The reader dies with this process (it is told which one to watch).
  std::vector<std::string> argv{core::helperProgram(kMeshReader), std::to_string(::getpid()), extension};
  if (path) argv.push_back(std::filesystem::absolute(*path).string());
  core::ChildResult result;
  try {
    result = core::runChild(argv, bytes, timeout, cancellation, {kLargePages});
  } catch (const std::system_error& error) {
    throw InvalidMeshError(fmt::format("the mesh reader could not be run: {}", error.what()));
  }
  std::string format = extension;
  std::transform(format.begin(), format.end(), format.begin(), [](unsigned char c) { return std::toupper(c); });
  if (result.status == core::ChildResult::Status::TimedOut) {
    throw InvalidMeshError(fmt::format(
        "the {} reader (Assimp) did not finish within {} s, many times what a file of this size takes: the file is "
        "malformed",
        format, std::chrono::duration_cast<std::chrono::seconds>(timeout).count()));
  }
  if (result.status == core::ChildResult::Status::Crashed && result.signal != 0) {
    throw InvalidMeshError(fmt::format("the {} reader (Assimp) crashed on this file ({}): the file is malformed",
                                       format, ::strsignal(result.signal)));
  }
  // Not the file's fault, as far as can be told: a reader that cannot load
  // its libraries exits with 127, and says so only on its standard error.
  if (result.status == core::ChildResult::Status::Crashed || result.output.empty()) {
    throw InvalidMeshError(
        fmt::format("the {} reader ({}) ended with status {} and no answer", format, argv[0], result.exitCode));
  }
  if (result.output[0] == 'E') throw InvalidMeshError(result.output.substr(1));
  if (result.output[0] == 'A') {
    std::string message = result.output.substr(1);
    // Assimp names the file by its whole path; the error starts with its name already.
    if (path) {
      const std::string where = std::filesystem::absolute(*path).string();
      for (size_t at; !where.empty() && (at = message.find(where)) != std::string::npos;)
        message.replace(at, where.size(), "it");
    }
    throw InvalidMeshError(explainReaderFailure(message, bytes, extension));
  }
  if (result.output[0] != 'M') throw InvalidMeshError(fmt::format("the {} reader's reply is not a mesh", format));
  return deserializeMesh(std::string_view(result.output).substr(1));
}

PolygonMesh readAny(std::string_view bytes, const std::string& extension, const std::filesystem::path* path,
                    const core::Cancellation* cancellation) {
  if (bytes.empty()) throw InvalidMeshError("the file is empty");
  if (auto mismatch = contentMismatch(bytes, extension)) throw InvalidMeshError(*mismatch);
  if (extension == "off") return readOff(bytes);
  if (extension == "ply") return readPly(bytes);
  // Assimp 5.2's glTF reader loops on text that is not JSON at all.
  if (extension == "gltf") {
    const size_t start = bytes.find_first_not_of(" \t\r\n");
    const bool bom = bytes.starts_with("\xEF\xBB\xBF");
    if (!bom && (start == std::string_view::npos || bytes[start] != '{')) {
      throw InvalidMeshError("the file is not glTF: a .gltf file is a JSON object, starting with '{'");
    }
  }
  return readWithAssimpHelper(bytes, extension, path, cancellation);
}

ImportedMesh finishImport(PolygonMesh mesh) {
  ImportedMesh result;
  const CleaningReport report = cleanMesh(mesh);
  std::vector<std::string> dropped;
  if (report.droppedFaces > 0) {
    dropped.push_back(fmt::format("{} face{} with fewer than 3 distinct vertices", report.droppedFaces,
                                  report.droppedFaces == 1 ? "" : "s"));
  }
  if (report.droppedVertices > 0) {
    dropped.push_back(
        fmt::format("{} unreferenced vert{}", report.droppedVertices, report.droppedVertices == 1 ? "ex" : "ices"));
  }
  if (!dropped.empty()) result.warnings.push_back(fmt::format("dropped {}", fmt::join(dropped, " and ")));
  if (mesh.faces.empty()) throw InvalidMeshError("the file holds no polygon faces");
  result.mesh = std::move(mesh);
  return result;
}

// Runs `read` and turns every failure into one InvalidMeshError line that
// starts with the file's name: nothing else escapes an import.
template <typename Read>
ImportedMesh withFileName(std::string_view displayName, Read read) {
  try {
    return read();
  } catch (const core::Cancelled&) {
    throw;
  } catch (const InvalidMeshError& error) {
    throw InvalidMeshError(fmt::format("{}: {}", displayName, error.what()));
  } catch (const std::bad_alloc&) {
    throw InvalidMeshError(fmt::format("{}: the mesh does not fit in memory", displayName));
  } catch (const std::exception& error) {
    // A reader's own failure (our readers throw only InvalidMeshError).
    throw InvalidMeshError(fmt::format("{}: {}", displayName, firstLine(error.what())));
  }
}

// Reads a whole regular file; refuses FIFOs and devices (which could block or
// never end) and says why a file cannot be opened.
std::string readRegularFile(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (status.type() == std::filesystem::file_type::not_found) throw InvalidMeshError("no such file");
  if (error) throw InvalidMeshError(fmt::format("cannot read the file: {}", error.message()));
  if (status.type() == std::filesystem::file_type::directory) throw InvalidMeshError("is a directory, not a mesh file");
  if (status.type() != std::filesystem::file_type::regular) {
    throw InvalidMeshError("is not a regular file (a pipe, device or socket); save the mesh to a file first");
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw InvalidMeshError(fmt::format("cannot open the file: {}", std::strerror(errno)));
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(file, &std::fclose);
  std::string bytes;
  char buffer[1 << 16];
  size_t got;
  while ((got = std::fread(buffer, 1, sizeof buffer, file)) > 0) bytes.append(buffer, got);
  if (std::ferror(file)) throw InvalidMeshError(fmt::format("cannot read the file: {}", std::strerror(errno)));
  return bytes;
}

std::string extensionOf(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  if (!extension.empty()) extension.erase(0, 1);
  return lowercase(extension);
}

}  // namespace

ImportedMesh importMesh(const std::filesystem::path& path, const core::Cancellation* cancellation) {
  return withFileName(path.string(), [&] {
    const std::string bytes = readRegularFile(path);
    return finishImport(readAny(bytes, extensionOf(path), &path, cancellation));
  });
}

ImportedMesh importMeshFromMemory(std::string_view bytes, std::string_view extension, std::string_view displayName) {
  return withFileName(displayName,
                      [&] { return finishImport(readAny(bytes, lowercase(extension), nullptr, nullptr)); });
}

CleaningReport cleanMesh(PolygonMesh& mesh) {
  CleaningReport report;
  // Weld: every vertex maps to the first vertex at exactly its position.
  struct PositionHash {
    size_t operator()(const Point3& p) const {
      size_t h = 0;
      for (int i = 0; i < 3; ++i) h = h * 1000003u ^ std::hash<double>{}(p[i]);
      return h;
    }
  };
  struct PositionEqual {
    bool operator()(const Point3& a, const Point3& b) const { return a == b; }
  };
  std::unordered_map<Point3, int, PositionHash, PositionEqual> firstAt;
  firstAt.reserve(mesh.positions.size());
  std::vector<int> weldedTo(mesh.positions.size());
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    Point3 key = mesh.positions[v];
    for (int i = 0; i < 3; ++i)
      if (key[i] == 0.0) key[i] = 0.0;  // -0 welds with +0
    weldedTo[v] = firstAt.emplace(key, v).first->second;
  }

  std::vector<std::vector<int>> kept;
  std::vector<int> keptSource;
  kept.reserve(mesh.faces.size());
  std::vector<char> referenced(mesh.positions.size(), 0);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    std::vector<int> corners;
    corners.reserve(face.size());
    for (int v : face) {
      const int w = weldedTo[v];
      if (corners.empty() || corners.back() != w) corners.push_back(w);
    }
    while (corners.size() > 1 && corners.front() == corners.back()) corners.pop_back();
    std::vector<int> distinct = corners;
    std::sort(distinct.begin(), distinct.end());
    if (std::unique(distinct.begin(), distinct.end()) - distinct.begin() < 3) {
      ++report.droppedFaces;
      continue;
    }
    for (int v : corners) referenced[v] = 1;
    kept.push_back(std::move(corners));
    keptSource.push_back(mesh.sourceFaceIndex(f));
  }

  std::vector<int> newIndex(mesh.positions.size(), -1);
  std::vector<Point3> positions;
  std::vector<int> positionSource;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (weldedTo[v] != v) continue;
    if (!referenced[v]) {
      ++report.droppedVertices;
      continue;
    }
    newIndex[v] = static_cast<int>(positions.size());
    positions.push_back(mesh.positions[v]);
    positionSource.push_back(mesh.sourceVertexIndex(v));
  }
  for (auto& face : kept)
    for (int& v : face) v = newIndex[v];
  mesh.positions = std::move(positions);
  mesh.faces = std::move(kept);
  mesh.sourceVertex = std::move(positionSource);
  mesh.sourceFace = std::move(keptSource);
  return report;
}

}  // namespace rotafab::geometry
