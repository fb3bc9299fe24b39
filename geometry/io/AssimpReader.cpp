#include "geometry/io/AssimpReader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>

#include <cstring>
#include <utility>
#include <vector>

namespace rotafab::geometry {
namespace {

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
      // Far more than the file could hold: not a damaged STL but another file.
      if (!exactBinary && 84 + 50ull * triangles > 4 * bytes.size() + 4096) {
        throw InvalidMeshError(fmt::format(
            "the file is not STL: it does not start with 'solid' (text STL), and as a binary STL its header would "
            "state {} triangles, {} times what its {} bytes hold",
            triangles, (84 + 50ull * triangles) / bytes.size(), bytes.size()));
      }
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

}  // namespace

PolygonMesh readWithAssimp(std::string_view bytes, const std::string& extension, const std::filesystem::path* path) {
  const StatedFaces stated = statedFaceCount(bytes, extension);
  Assimp::Importer importer;
  // No post-processing that changes the mesh: polygons stay polygons, we weld
  // ourselves; Assimp's own validation refuses broken scene structures.
  constexpr unsigned kFlags = aiProcess_ValidateDataStructure;
  const aiScene* scene = path ? importer.ReadFile(path->string(), kFlags)
                              : importer.ReadFileFromMemory(bytes.data(), bytes.size(), kFlags, extension.c_str());
  if (!scene || !scene->mRootNode) throw AssimpFailure(firstLine(importer.GetErrorString()));
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

}  // namespace rotafab::geometry
