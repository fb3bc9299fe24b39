#pragma once
// Discrete curvature (dissertation III.2): the face defect of eq. 3.3, the
// vertex defect (angle deficit), and the discrete Gauss-Bonnet theorem
// (eq. 3.4-3.5, after Akleman et al.) in the form the band decomposition
// relies on: once vertex and edge bands are flat, all curvature sits in the
// holes, and the holes' defects add up to 2 pi chi.
//
// Corner angles are unsigned 3D angles between the two sides at the corner,
// so a reflex corner of a planar polygon counts as 2 pi minus its angle.

#include <vector>

#include "geometry/PolygonMesh.h"
#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

// The angle at corner i of face f, in radians, in [0, pi].
double cornerAngle(const PolygonMesh& mesh, int face, int corner);

// Eq. 3.3: phi = sum_i theta_i - (n - 2) pi for an n-sided face.
double faceDefect(const PolygonMesh& mesh, int face);

// 2 pi minus the angles around an interior vertex; pi minus them at a boundary
// vertex (its geodesic curvature).
double vertexDefect(const PolygonMesh& mesh, const RotationSystem& rs, int vertex);

// Discrete Gauss-Bonnet (Akleman et al., III.2.2): the vertex defects plus the
// face defects of eq. 3.3 add up to 2 pi (V - E + F) on any oriented manifold
// mesh, closed or with boundary. With planar faces the face defects vanish and
// the vertex defects alone give 2 pi chi.
double totalVertexDefect(const PolygonMesh& mesh, const RotationSystem& rs);
double totalFaceDefect(const PolygonMesh& mesh);

// The curvature of a structure whose material is the faces with isHole[f]
// false: a hole's corner angle is what the material leaves of 2 pi at that
// vertex, and a hole's defect is eq. 3.3 with those angles. Returns the sum of
// the holes' defects plus the material faces' own defects (zero for planar
// material). On a closed mesh in which every vertex lies on exactly one hole
// (a corner-cut mesh with its face copies as holes) this equals 2 pi chi.
double holeAndMaterialDefect(const PolygonMesh& mesh, const std::vector<char>& isHole);

}  // namespace rotafab::geometry
