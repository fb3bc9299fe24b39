// Import: every supported path reads what the file holds, and every bad input
// is refused with one line that names the file and what is wrong.

#include "geometry/io/MeshImport.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include <fmt/format.h>
#include <sys/stat.h>
#include <cmath>

#include <cstring>

#include "geometry/Primitives.h"
#include "geometry/io/ObjWriter.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

using test::TempDir;

// The message of the InvalidMeshError that importing `path` throws.
std::string refusal(const std::filesystem::path& path) {
  try {
    importMesh(path);
  } catch (const InvalidMeshError& error) {
    return error.what();
  }
  return "(accepted)";
}

std::string objOf(const PolygonMesh& mesh) {
  std::ostringstream out;
  writeObj(out, mesh);
  return out.str();
}

constexpr const char* kCgalStyleOff =
    "OFF\n"
    "# written by CGAL: a square and a triangle, per-face colours\n"
    "5 2 0\n"
    "\n"
    "# vertices\n"
    "0 0 0\n"
    "1 0 0\n"
    "1 1 0 # a trailing comment\n"
    "0 1 0\n"
    "2 0.5 0\n"
    "# faces\n"
    "4 0 1 2 3 255 0 0\n"
    "3 1 4 2 0.5 0.5 0.5 1\n";

TEST(MeshImport, OffWithCommentsAndFaceColoursLoadsEveryFace) {
  TempDir dir;
  const ImportedMesh imported = importMesh(dir.write("square.off", kCgalStyleOff));
  ASSERT_EQ(imported.mesh.faceCount(), 2);
  EXPECT_EQ(imported.mesh.faces[0], (std::vector<int>{0, 1, 2, 3}));  // polygons are kept
  EXPECT_EQ(imported.mesh.faces[1], (std::vector<int>{1, 4, 2}));
  EXPECT_EQ(imported.mesh.vertexCount(), 5);
  EXPECT_TRUE(imported.warnings.empty());
}

TEST(MeshImport, OffVariantsAndCountsOnTheHeaderLine) {
  TempDir dir;
  EXPECT_EQ(importMesh(dir.write("a.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")).mesh.faceCount(), 1);
  EXPECT_EQ(importMesh(dir.write("b.off", "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n3 0 1 2\n"))
                .mesh.faceCount(),
            1);
  EXPECT_EQ(refusal(dir.write("c.off", "4OFF\n3 1 0\n")),
            dir.path() / "c.off" += ": line 1: '4OFF' (4D or nD) files are not supported; 3D OFF is");
}

TEST(MeshImport, ObjKeepsPolygonsAndWeldsGroups) {
  TempDir dir;
  // Two groups that repeat the shared vertices, as exporters write them.
  const auto path = dir.write("groups.obj",
                              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng a\nf 1 2 3 4\n"
                              "v 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\ng b\nusemtl other\nf 5 6 7 8\n");
  const ImportedMesh imported = importMesh(path);
  EXPECT_EQ(imported.mesh.vertexCount(), 6);
  ASSERT_EQ(imported.mesh.faceCount(), 2);
  EXPECT_EQ(imported.mesh.faces[0].size(), 4u);
  const MeshTopology t = test::topologyOf(imported.mesh);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.edges, 7);
}

TEST(MeshImport, StlTriangleSoupIsWelded) {
  // Binary and ASCII STL of a cube: 12 triangles, 36 corners, 8 distinct positions.
  PolygonMesh cubeMesh = cube();
  std::string ascii = "solid cube\n";
  std::string binary(80, '\0');
  const uint32_t triangles = 12;
  binary.append(reinterpret_cast<const char*>(&triangles), 4);
  for (const auto& quad : cubeMesh.faces) {
    for (int t = 0; t < 2; ++t) {
      const int corners[3] = {quad[0], quad[1 + t], quad[2 + t]};
      ascii += "facet normal 0 0 0\n outer loop\n";
      float record[12] = {0, 0, 0};
      for (int c = 0; c < 3; ++c) {
        const Point3& p = cubeMesh.positions[corners[c]];
        ascii += fmt::format("  vertex {} {} {}\n", p.x(), p.y(), p.z());
        for (int a = 0; a < 3; ++a) record[3 + 3 * c + a] = static_cast<float>(p[a]);
      }
      ascii += " endloop\nendfacet\n";
      binary.append(reinterpret_cast<const char*>(record), sizeof record);
      binary.append(2, '\0');
    }
  }
  ascii += "endsolid cube\n";
  TempDir dir;
  for (const auto& path : {dir.write("ascii.stl", ascii), dir.write("binary.stl", binary)}) {
    SCOPED_TRACE(path.string());
    const ImportedMesh imported = importMesh(path);
    const MeshTopology t = test::topologyOf(imported.mesh);
    EXPECT_EQ(t.vertices, 8);
    EXPECT_EQ(t.edges, 18);
    EXPECT_EQ(t.faces, 12);
    EXPECT_EQ(t.genus, 0);
    EXPECT_TRUE(t.manifold);
  }
  // A binary STL cut short is refused, not read short.
  EXPECT_EQ(
      refusal(dir.write("short.stl", binary.substr(0, 84 + 50 * 7))),
      (dir.path() / "short.stl").string() + ": truncated: the binary STL header states 12 triangles, the file holds 7");
  // An ASCII STL whose last facet is cut off.
  EXPECT_NE(refusal(dir.write("short-ascii.stl", ascii.substr(0, ascii.size() - 60))), "(accepted)");
}

TEST(MeshImport, PlyAsciiAndBinaryInBothByteOrders) {
  const std::string header =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const float points[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const int faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
  auto binaryBody = [&](bool bigEndian) {
    std::string body;
    auto put = [&](const void* data, size_t size) {
      std::string bytes(static_cast<const char*>(data), size);
      if (bigEndian) std::reverse(bytes.begin(), bytes.end());
      body += bytes;
    };
    for (const auto& p : points) {
      for (float c : p) put(&c, 4);
      body += '\x07';  // red
    }
    for (const auto& f : faces) {
      body += '\x03';
      for (int i : f) put(&i, 4);
    }
    return body;
  };
  TempDir dir;
  const auto ascii = dir.write("a.ply", "ply\nformat ascii 1.0\ncomment made by hand\n" + header +
                                            "0 0 0 7\n1 0 0 7\n1 1 0 7\n0 1 0 7\n3 0 1 2\n3 0 2 3\n");
  const auto little = dir.write("l.ply", "ply\nformat binary_little_endian 1.0\n" + header + binaryBody(false));
  const auto big = dir.write("b.ply", "ply\nformat binary_big_endian 1.0\n" + header + binaryBody(true));
  for (const auto& path : {ascii, little, big}) {
    SCOPED_TRACE(path.string());
    const ImportedMesh imported = importMesh(path);
    ASSERT_EQ(imported.mesh.faceCount(), 2);
    EXPECT_EQ(imported.mesh.faces[1], (std::vector<int>{0, 2, 3}));
    EXPECT_EQ(imported.mesh.positions[2], Point3(1, 1, 0));
  }
  const std::string truncated = "ply\nformat binary_little_endian 1.0\n" + header + binaryBody(false);
  EXPECT_EQ(
      refusal(dir.write("t.ply", truncated.substr(0, truncated.size() - 5))),
      (dir.path() / "t.ply").string() + ": truncated: the header states 2 'face' elements, the file ends after 1");
}

// Formats Assimp writes as well as reads: a round trip through its exporter.
TEST(MeshImport, GltfBinaryAnd3mfThroughAssimp) {
  TempDir dir;
  const auto source = dir.write("ball.obj", objOf(truncatedIcosahedron()));
  Assimp::Importer importer;
  // Assimp's 3MF exporter writes only the first three corners of a polygon,
  // and glTF holds triangles only: hand the exporters triangles.
  const aiScene* scene = importer.ReadFile(source.string(), aiProcess_Triangulate);
  ASSERT_NE(scene, nullptr);
  Assimp::Exporter exporter;
  for (auto [format, name] : {std::pair{"glb2", "ball.glb"}, {"3mf", "ball.3mf"}, {"stlb", "ball.stl"}}) {
    SCOPED_TRACE(format);
    ASSERT_EQ(exporter.Export(scene, format, (dir.path() / name).string()), AI_SUCCESS) << exporter.GetErrorString();
    const MeshTopology t = test::topologyOf(importMesh(dir.path() / name).mesh);
    EXPECT_EQ(t.vertices, 60);
    EXPECT_EQ(t.euler, 2);
    EXPECT_EQ(t.genus, 0);
    EXPECT_TRUE(t.manifold);
  }
}

TEST(MeshImport, DegenerateFacesAndUnreferencedVerticesAreDroppedWithOneWarning) {
  TempDir dir;
  // Face 1 collapses to an edge after welding (vertices 3 and 0 coincide); vertex 4 is unused.
  const auto path = dir.write("d.off", "OFF\n5 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 0\n9 9 9\n3 0 1 2\n3 1 3 0\n");
  const ImportedMesh imported = importMesh(path);
  EXPECT_EQ(imported.mesh.faceCount(), 1);
  EXPECT_EQ(imported.mesh.vertexCount(), 3);
  ASSERT_EQ(imported.warnings.size(), 1u);
  EXPECT_EQ(imported.warnings[0], "dropped 1 face with fewer than 3 distinct vertices and 1 unreferenced vertex");
}

TEST(MeshImport, EveryUnreadableInputIsRefusedWithOneLine) {
  TempDir dir;
  const std::string d = dir.path().string() + "/";
  struct Case {
    std::string file, bytes, message;
  };
  const std::vector<Case> cases = {
      {"empty.obj", "", "the file is empty"},
      {"empty.off", "", "the file is empty"},
      {"comments.off", "# nothing\n", "the file is empty"},
      {"short.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n",
       "truncated: the header states 2 faces, the file ends after 1"},
      {"shortv.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n", "truncated: the header states 4 vertices, the file ends after 2"},
      {"range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
       "line 6: face 0 refers to vertex 7, but the file has 3 vertices (0 to 2)"},
      {"negative.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
       "line 6: face 0 refers to vertex -1, but the file has 3 vertices (0 to 2)"},
      {"nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n",
       "line 4: vertex 1 has a non-finite coordinate (1, nan, 0)"},
      {"inf.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 -inf\n3 0 1 2\n",
       "line 5: vertex 2 has a non-finite coordinate (0, 1, -inf)"},
      {"huge.off", "OFF\n99999999999 1 0\n",
       "line 2: the header states 99999999999 vertices and 1 faces, more than a 20-byte file can hold"},
      {"word.off", "OFF\n3 1 0\n0 0 0\n1 zero 0\n", "line 4: vertex 1: 'zero' is not a number"},
      {"nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", "vertex 1 has a non-finite coordinate (1, 0, nan)"},
      {"range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
       "line 4: the face refers to vertex 9, but the file has 3 vertices"},
      {"back.obj", "v 0 0 0\nv 1 0 0\nf 1 2 -3\nv 0 1 0\n",
       "line 3: the face refers to vertex -3 (counted back), but only 2 vertices come before it"},
      {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 0\n",
       "line 5: the face's corner '0' is not a vertex number (1 and up, or -1 and down)"},
      {"points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "the file holds no polygon faces"},
      {"obj.stl", "# saved by a script\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
       "the file is text, not STL (a text STL starts with 'solid'): it looks like OBJ; rename it to .obj"},
      {"off.ply", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
       "the file is not PLY: it looks like OFF; rename it to .off"},
      {"stl.obj", "solid x\nfacet normal 0 0 1\n", "the file is not OBJ: it looks like text STL; rename it to .stl"},
      {"utf16.obj", std::string("\xFF\xFEv\0 \0001\0", 8),
       "the file is UTF-16 text; OBJ is read as UTF-8 or ASCII: save it again as UTF-8"},
      {"noscene.gltf", "{\"asset\":{\"version\":\"2.0\"}}", "the file holds no polygon faces"},
      {"chunk.3ds", std::string("\x4d\x4d\xff\xff\xff\x7f", 6) + std::string(40, 'x'),
       "the 3DS file is malformed: chunk is too large"},
      {"lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", "the file holds no polygon faces"},
      {"range.ply",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
       "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
       "line 13: face 0 refers to vertex 3, but the file has 3 vertices (0 to 2)"},
      {"noheader.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "truncated: the header has no end_header line"},
      {"mesh.xyz", "1 2 3\n", "the file is not XYZ, or is malformed: its contents are not what a .xyz file holds"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    EXPECT_EQ(refusal(dir.write(c.file, c.bytes)), d + c.file + ": " + c.message);
  }
  EXPECT_EQ(refusal(dir.path() / "missing.obj"), d + "missing.obj: no such file");
  EXPECT_EQ(refusal(dir.path()), dir.path().string() + ": is a directory, not a mesh file");
}

// Assimp aborts on this file; the import runs it in a child process and says so.
TEST(MeshImport, ReaderThatAbortsIsRefusedNotFatal) {
  const auto path = std::filesystem::path(ROTAFAB_SOURCE_DIR) / "tests/data/regressions/assimp-3mf-abort.3mf";
  EXPECT_EQ(refusal(path),
            path.string() + ": the 3MF reader (Assimp) crashed on this file (Aborted): the file is malformed");
}

// Assimp's own test model with infinite coordinates (package assimp-testmodels).
TEST(MeshImport, GltfWithInfinitiesIsRefused) {
  const std::filesystem::path path = "/usr/share/assimp/models/glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb";
  ASSERT_TRUE(std::filesystem::exists(path)) << "install assimp-testmodels with scripts/setup.sh";
  EXPECT_EQ(refusal(path), path.string() + ": vertex 0 has a non-finite coordinate (-inf, -0.5, 0.5)");
}

TEST(MeshImport, PipesAndDevicesAreRefusedNotWaitedOn) {
  TempDir dir;
  const auto fifo = dir.path() / "mesh.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(refusal(fifo),
            fifo.string() + ": is not a regular file (a pipe, device or socket); save the mesh to a file first");
  EXPECT_EQ(refusal("/dev/zero"),
            "/dev/zero: is not a regular file (a pipe, device or socket); save the mesh to a file first");
}

// After welding and dropping, messages still name vertices and faces as the file numbers them.
TEST(MeshImport, MessagesUseTheFilesNumberingAfterCleaning) {
  TempDir dir;
  // Vertex 0 is unused, vertex 6 duplicates vertex 1, face 0 is degenerate:
  // cleaning renumbers everything, yet the fin edge is (1, 2) in faces 1, 2, 3.
  const auto path = dir.write("fin.off",
                              "OFF\n7 4 0\n9 9 9\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 0\n"
                              "3 1 1 2\n3 1 2 3\n3 2 6 4\n3 1 2 5\n");
  ImportedMesh imported = importMesh(path);
  const MeshAnalysis analysis = analyzeMesh(imported.mesh);
  ASSERT_EQ(analysis.problems.size(), 1u);
  EXPECT_EQ(analysis.problems[0].message, "edge (1, 2) is shared by 3 faces (1, 2, 3)");
}

// A base64 data URI for a glTF buffer.
std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    uint32_t chunk = 0;
    for (size_t k = 0; k < 3; ++k) chunk = chunk << 8 | (k < n ? static_cast<uint8_t>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(chunk >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// A glTF 2.0 scene of one tetrahedron mesh placed by two nodes.
std::string gltfWithTwoInstances(const std::string& firstNode, const std::string& secondNode) {
  const PolygonMesh tet = tetrahedron();
  std::string buffer;
  for (const auto& p : tet.positions) {
    for (int a = 0; a < 3; ++a) {
      const float c = static_cast<float>(p[a]);
      buffer.append(reinterpret_cast<const char*>(&c), 4);
    }
  }
  for (const auto& face : tet.faces) {
    for (int v : face) {
      const uint16_t index = static_cast<uint16_t>(v);
      buffer.append(reinterpret_cast<const char*>(&index), 2);
    }
  }
  return fmt::format(
      R"({{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],)"
      R"("nodes":[{},{}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],)"
      R"("buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}],)"
      R"("bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":24}}],)"
      R"("accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]}},)"
      R"({{"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}}]}})",
      firstNode, secondNode, buffer.size(), base64(buffer));
}

TEST(MeshImport, GltfNodeTransformsPlaceEveryInstance) {
  TempDir dir;
  const auto path = dir.write("two.gltf", gltfWithTwoInstances(R"({"mesh":0,"translation":[10,0,0]})",
                                                               R"({"mesh":0,"translation":[-10,0,0]})"));
  const ImportedMesh imported = importMesh(path);
  const MeshTopology t = test::topologyOf(imported.mesh);
  EXPECT_EQ(t.components, 2);
  EXPECT_EQ(t.vertices, 8);
  EXPECT_EQ(t.genus, 0);
  double minX = 1e9, maxX = -1e9;
  for (const auto& p : imported.mesh.positions) {
    minX = std::min(minX, p.x());
    maxX = std::max(maxX, p.x());
  }
  EXPECT_DOUBLE_EQ(minX, -11.0);
  EXPECT_DOUBLE_EQ(maxX, 11.0);
  // A transform that overflows single precision is refused, not passed on as infinities.
  const auto huge = dir.write(
      "huge.gltf",
      gltfWithTwoInstances(R"({"mesh":0,"scale":[3e38,3e38,3e38],"translation":[3e38,0,0]})", R"({"mesh":0})"));
  EXPECT_NE(refusal(huge).find("the scene's node transform makes it non-finite"), std::string::npos) << refusal(huge);
}

// Found by the fuzzer: Assimp 5.2's glTF reader never returns on these 39
// bytes. Refused at once, saying what a .gltf file must be.
TEST(MeshImport, AGltfThatIsNotJsonIsRefusedAtOnce) {
  TempDir dir;
  const auto path = dir.write("scan.gltf", "ply\nformat binary_little_endian 1.0\ncom");
  const std::string why = refusal(path);
  EXPECT_NE(why.find("scan.gltf: the file is not glTF: a .gltf file is a JSON object"), std::string::npos) << why;
}

// Whatever the bytes, import ends in a mesh or an InvalidMeshError: never a
// crash, a hang or another exception. (The fuzz target goes much further.)
TEST(MeshImport, RandomAndCorruptedBytesNeverEscapeAsAnythingButInvalidMesh) {
  std::mt19937 random(20261122);
  const std::string seeds[] = {
      kCgalStyleOff, objOf(cube()),
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
      "float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 "
      "0\n0 1 0\n3 0 1 2\n"};
  const char* extensions[] = {"off", "obj", "ply", "stl"};
  for (int round = 0; round < 400; ++round) {
    std::string bytes = seeds[round % 3];
    const int edits = 1 + random() % 8;
    for (int e = 0; e < edits && !bytes.empty(); ++e) {
      const size_t at = random() % bytes.size();
      switch (random() % 3) {
        case 0:
          bytes[at] = static_cast<char>(random());
          break;
        case 1:
          bytes.erase(at, 1 + random() % 16);
          break;
        default:
          bytes.insert(at, std::string(1 + random() % 4, "0123456789 -.\n#ef"[random() % 17]));
          break;
      }
    }
    try {
      importMeshFromMemory(bytes, extensions[round % 4], "fuzzed");
    } catch (const InvalidMeshError& error) {
      EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace rotafab::geometry
