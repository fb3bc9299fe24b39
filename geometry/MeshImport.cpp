#include "geometry/MeshImport.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <unordered_map>

#include "geometry/IsolatedCall.h"
#include "geometry/MeshReaders.h"

namespace rotafab::geometry {
namespace {

std::string lowercase(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return lower;
}

bool startsWithWord(std::string_view line, std::string_view word) {
  size_t i = line.find_first_not_of(" \t");
  if (i == std::string_view::npos) return false;
  line.remove_prefix(i);
  return line.size() > word.size() && line.substr(0, word.size()) == word &&
         (line[word.size()] == ' ' || line[word.size()] == '\t');
}

// Lines whose first word is `word`.
long long countLinesStartingWith(std::string_view bytes, std::string_view word) {
  long long count = 0;
  size_t position = 0;
  while (position < bytes.size()) {
    size_t end = bytes.find('\n', position);
    if (end == std::string_view::npos) end = bytes.size();
    if (startsWithWord(bytes.substr(position, end - position), word)) ++count;
    position = end + 1;
  }
  return count;
}

// The faces a file states, where that can be counted cheaply; Assimp's result
// is compared with it so that a short read is refused, not passed on.
struct StatedFaces {
  long long count = -1;       // -1: unknown
  bool polygonsOnly = false;  // count only faces with 3 or more corners
};

StatedFaces statedFaceCount(std::string_view bytes, const std::string& extension) {
  StatedFaces stated;
  if (extension == "obj") {
    // Each `f` line with at least three vertex references is one polygon.
    stated.count = 0;
    stated.polygonsOnly = true;
    size_t position = 0;
    while (position < bytes.size()) {
      size_t end = bytes.find('\n', position);
      if (end == std::string_view::npos) end = bytes.size();
      std::string_view line = bytes.substr(position, end - position);
      position = end + 1;
      if (!startsWithWord(line, "f")) continue;
      int references = 0;
      bool inWord = false;
      for (char c : line.substr(line.find('f') + 1)) {
        if (c == '#') break;
        const bool space = c == ' ' || c == '\t' || c == '\r' || c == '\\';
        if (!space && !inWord) ++references;
        inWord = !space;
      }
      if (references >= 3) ++stated.count;
    }
  } else if (extension == "stl") {
    // Binary when the size is exactly what the header's triangle count makes it
    // (some binary headers start with "solid"), or when it does not start, after
    // white space, with "solid" (as Assimp decides).
    uint32_t triangles = 0;
    if (bytes.size() >= 84) std::memcpy(&triangles, bytes.data() + 80, 4);
    const bool exactBinary = bytes.size() >= 84 && bytes.size() == 84 + 50ull * triangles;
    const size_t text = bytes.find_first_not_of(" \t\r\n");
    const bool looksAscii = text != std::string_view::npos && bytes.substr(text, 5) == "solid";
    if (exactBinary || (!looksAscii && bytes.size() >= 84)) {
      stated.count = triangles;
      if (bytes.size() < 84 + 50ull * triangles) {
        throw InvalidMeshError(fmt::format("truncated: the binary STL header states {} triangles, the file holds {}",
                                           triangles, (bytes.size() - 84) / 50));
      }
    } else if (looksAscii) {
      stated.count = countLinesStartingWith(bytes, "facet");
    }
  }
  return stated;
}

// Appends every mesh instance of the scene with its node transform (an explicit
// stack: a deep node tree in a hostile file must not overflow ours).
void appendScene(const aiScene& scene, PolygonMesh& mesh, long long& polygonCount, long long& faceCount) {
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> pending{{scene.mRootNode, aiMatrix4x4()}};
  while (!pending.empty()) {
    auto [node, parentTransform] = pending.back();
    pending.pop_back();
    const aiMatrix4x4 transform = parentTransform * node->mTransformation;
    for (unsigned n = 0; n < node->mNumMeshes; ++n) {
      if (!scene.mMeshes || node->mMeshes[n] >= scene.mNumMeshes || !scene.mMeshes[node->mMeshes[n]]) continue;
      const aiMesh& source = *scene.mMeshes[node->mMeshes[n]];
      if (!source.mVertices || !source.mFaces) continue;
      const int base = mesh.vertexCount();
      for (unsigned v = 0; v < source.mNumVertices; ++v) {
        // Checked before the transform, which would spread a NaN to all three coordinates.
        const Point3 raw(source.mVertices[v].x, source.mVertices[v].y, source.mVertices[v].z);
        if (!raw.allFinite()) {
          throw InvalidMeshError(fmt::format("vertex {} has a non-finite coordinate {}", base + v, formatPoint(raw)));
        }
        const aiVector3D p = transform * source.mVertices[v];
        mesh.positions.emplace_back(p.x, p.y, p.z);
        if (!mesh.positions.back().allFinite()) {
          throw InvalidMeshError(fmt::format("vertex {} at {}: the scene's node transform makes it non-finite {}",
                                             base + v, formatPoint(raw), formatPoint(mesh.positions.back())));
        }
      }
      for (unsigned f = 0; f < source.mNumFaces; ++f) {
        const aiFace& face = source.mFaces[f];
        ++faceCount;
        if (face.mNumIndices < 3 || !face.mIndices) continue;  // points and lines are not surface
        ++polygonCount;
        std::vector<int> corners;
        corners.reserve(face.mNumIndices);
        for (unsigned i = 0; i < face.mNumIndices; ++i) {
          if (face.mIndices[i] >= source.mNumVertices) {
            throw InvalidMeshError(fmt::format("face {} refers to vertex {}, but its mesh has {} vertices",
                                               faceCount - 1, face.mIndices[i], source.mNumVertices));
          }
          corners.push_back(base + static_cast<int>(face.mIndices[i]));
        }
        mesh.faces.push_back(std::move(corners));
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) {
      if (node->mChildren && node->mChildren[c]) pending.emplace_back(node->mChildren[c], transform);
    }
  }
}

std::string firstLine(const char* text) {
  std::string line = text ? text : "";
  if (size_t end = line.find('\n'); end != std::string::npos) line.resize(end);
  return line.empty() ? "the file could not be read" : line;
}

PolygonMesh readWithAssimp(std::string_view bytes, const std::string& extension, const std::filesystem::path* path) {
  const StatedFaces stated = statedFaceCount(bytes, extension);
  Assimp::Importer importer;
  // No post-processing that changes the mesh: polygons stay polygons, we weld
  // ourselves; Assimp's own validation refuses broken scene structures.
  constexpr unsigned kFlags = aiProcess_ValidateDataStructure;
  const aiScene* scene = path ? importer.ReadFile(path->string(), kFlags)
                              : importer.ReadFileFromMemory(bytes.data(), bytes.size(), kFlags, extension.c_str());
  if (!scene || !scene->mRootNode) throw InvalidMeshError(firstLine(importer.GetErrorString()));
  PolygonMesh mesh;
  long long polygons = 0, faces = 0;
  appendScene(*scene, mesh, polygons, faces);
  const long long read = stated.polygonsOnly ? polygons : faces;
  if (stated.count >= 0 && read < stated.count) {
    throw InvalidMeshError(fmt::format(
        "only {} of the {} faces in the file could be read (malformed or truncated file)", read, stated.count));
  }
  return mesh;
}

// The mesh as bytes, to come back from the child process that read it:
// counts, the coordinates as one block, then each face's size and corners.
static_assert(sizeof(Point3) == 3 * sizeof(double), "Point3 is three packed doubles");

std::string serialize(const PolygonMesh& mesh) {
  size_t corners = 0;
  for (const auto& face : mesh.faces) corners += face.size();
  std::string out;
  out.reserve(16 + mesh.positions.size() * sizeof(Point3) + mesh.faces.size() * 4 + corners * sizeof(int));
  auto put = [&](const void* data, size_t size) { out.append(static_cast<const char*>(data), size); };
  const uint64_t vertices = mesh.positions.size(), faces = mesh.faces.size();
  put(&vertices, sizeof vertices);
  put(mesh.positions.data(), mesh.positions.size() * sizeof(Point3));
  put(&faces, sizeof faces);
  for (const auto& face : mesh.faces) {
    const uint32_t size = static_cast<uint32_t>(face.size());
    put(&size, sizeof size);
    put(face.data(), face.size() * sizeof(int));
  }
  return out;
}

PolygonMesh deserialize(std::string_view bytes) {
  size_t at = 0;
  auto take = [&](void* into, uint64_t size) {
    if (size > bytes.size() - at) throw InvalidMeshError("the reader's result was cut short");
    std::memcpy(into, bytes.data() + at, size);
    at += size;
  };
  PolygonMesh mesh;
  uint64_t vertices = 0, faces = 0;
  take(&vertices, sizeof vertices);
  if (vertices > bytes.size() / sizeof(Point3)) throw InvalidMeshError("the reader's result was cut short");
  mesh.positions.resize(vertices);
  take(mesh.positions.data(), vertices * sizeof(Point3));
  take(&faces, sizeof faces);
  if (faces > bytes.size() / sizeof(uint32_t)) throw InvalidMeshError("the reader's result was cut short");
  mesh.faces.resize(faces);
  for (auto& face : mesh.faces) {
    uint32_t size = 0;
    take(&size, sizeof size);
    if (size > bytes.size() / sizeof(int)) throw InvalidMeshError("the reader's result was cut short");
    face.resize(size);
    take(face.data(), size * sizeof(int));
  }
  return mesh;
}

// Assimp in a child process (IsolatedCall.h): Debian's Assimp 5.2 aborts on
// some malformed files (its assertions are on) and may crash or hang on others;
// any of that becomes one clear error here instead of taking rotafab down.
PolygonMesh readWithAssimpIsolated(std::string_view bytes, const std::string& extension,
                                   const std::filesystem::path* path, const core::Cancellation* cancellation) {
  // Generous: Assimp reads 200k faces of OBJ in about 0.15 s.
  const auto timeout = std::chrono::seconds(120 + bytes.size() / 1'000'000);
  const IsolatedResult result = runIsolated(
      [&]() -> std::string {
        // A tag byte, then the mesh ('M') or the one-line error ('E').
        std::string reply;
        try {
          const std::string mesh = serialize(readWithAssimp(bytes, extension, path));
          reply.append("M").append(mesh);
        } catch (const InvalidMeshError& error) {
          reply.assign("E").append(error.what());
        } catch (const std::bad_alloc&) {
          reply.assign("Ethe mesh does not fit in memory");
        } catch (const std::exception& error) {
          reply.assign("E").append(firstLine(error.what()));
        }
        return reply;
      },
      timeout, cancellation);
  std::string format = extension;
  std::transform(format.begin(), format.end(), format.begin(), [](unsigned char c) { return std::toupper(c); });
  if (result.status == IsolatedResult::Status::TimedOut) {
    throw InvalidMeshError(fmt::format("the {} reader (Assimp) did not finish within {} s", format,
                                       std::chrono::duration_cast<std::chrono::seconds>(timeout).count()));
  }
  if (result.status == IsolatedResult::Status::Crashed || result.output.empty()) {
    throw InvalidMeshError(fmt::format("the {} reader (Assimp) crashed on this file{}: the file is malformed", format,
                                       result.signal ? fmt::format(" ({})", ::strsignal(result.signal)) : ""));
  }
  if (result.output[0] == 'E') throw InvalidMeshError(result.output.substr(1));
  return deserialize(std::string_view(result.output).substr(1));
}

PolygonMesh readAny(std::string_view bytes, const std::string& extension, const std::filesystem::path* path,
                    const core::Cancellation* cancellation) {
  if (bytes.empty()) throw InvalidMeshError("the file is empty");
  if (extension == "off") return readOff(bytes);
  if (extension == "ply") return readPly(bytes);
  return readWithAssimpIsolated(bytes, extension, path, cancellation);
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
    // Assimp throws DeadlyImportError and others on some malformed inputs.
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
