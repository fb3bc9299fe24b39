// The mesh reader's reply (geometry/io/MeshWire.h): a mesh comes back as it
// went, and bytes that are no mesh are refused before anything uses them.

#include "geometry/io/MeshWire.h"

#include <gtest/gtest.h>

#include <cstring>

#include "geometry/Primitives.h"

namespace rotafab::geometry {
namespace {

TEST(MeshWire, AMeshComesBackAsItWent) {
  const PolygonMesh mesh = truncatedIcosahedron();
  const PolygonMesh back = deserializeMesh(serializeMesh(mesh));
  EXPECT_EQ(back.positions, mesh.positions);
  EXPECT_EQ(back.faces, mesh.faces);
}

TEST(MeshWire, BytesThatAreNoMeshAreRefused) {
  const std::string good = serializeMesh(cube());
  EXPECT_THROW(deserializeMesh(good.substr(0, good.size() - 1)), InvalidMeshError);
  EXPECT_THROW(deserializeMesh(good + "x"), InvalidMeshError);
  // The last corner of the last face pointing past the vertices.
  std::string outOfRange = good;
  const int past = 8;
  std::memcpy(outOfRange.data() + outOfRange.size() - sizeof(int), &past, sizeof past);
  EXPECT_THROW(deserializeMesh(outOfRange), InvalidMeshError);
  // A coordinate that is not a number.
  std::string notANumber = good;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(notANumber.data() + 8, &nan, sizeof nan);
  EXPECT_THROW(deserializeMesh(notANumber), InvalidMeshError);
}

}  // namespace
}  // namespace rotafab::geometry
