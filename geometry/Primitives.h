#pragma once
// Meshes built in code: the examples we ship and the fixtures of the tests.
// Every closed mesh here is oriented outwards (counter-clockwise faces seen
// from outside).

#include <functional>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// The convex hull of points in general convex position, one polygon per
// supporting plane (coplanar hull points make one face). For small point sets
// (brute force, O(n^4)).
PolygonMesh convexPolytope(const std::vector<Point3>& points);

PolygonMesh tetrahedron();
PolygonMesh cube();  // 6 quads
PolygonMesh octahedron();
PolygonMesh dodecahedron();  // 12 pentagons
PolygonMesh icosahedron();
PolygonMesh truncatedIcosahedron();  // the "soccer ball": 12 pentagons, 20 hexagons

// A torus of quads: `around` segments along the major circle, `across` along
// the minor one.
PolygonMesh torus(int around, int across, double majorRadius = 2.0, double minorRadius = 0.75);

// The boundary of a set of unit voxels in a box of nx x ny x nz: quads,
// outward. The set must not touch itself along an edge or at a vertex only.
PolygonMesh voxelSurface(int nx, int ny, int nz, const std::function<bool(int, int, int)>& filled);

// A slab with two square holes through it: a closed surface of genus 2.
PolygonMesh genusTwoSlab();

// An open disc: a fan of `segments` triangles around a centre (one boundary loop).
PolygonMesh disc(int segments);

// A Moebius strip of `segments` quads: non-orientable, one boundary loop.
PolygonMesh moebiusStrip(int segments);

}  // namespace rotafab::geometry
