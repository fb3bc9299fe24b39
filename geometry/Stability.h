#pragma once
// Will it stand? The dissertation's bunny fell forward once it was built
// (ch. VII): its centre of mass was not over the area it stood on, and it had
// to be hung from two points. Before anything is cut, the built structure's
// mass and centre of mass are found from its panels (each panel's 3D
// surface, its area times the sheet's areal density, and the fasteners in
// its holes), and so is the footprint it rests on when the `up` axis points
// up: the convex hull, seen from above, of the points of the panels that
// touch the ground. It stands when the centre of mass lies above the
// footprint; the margin says by how much (inside) or how far it misses
// (outside). When it falls, two points of the structure above its centre of
// mass, with the centre of mass between them seen from above where the
// shape has such a pair (else as near as it has), say where to hang it.

#include <optional>
#include <vector>

#include "geometry/Structure.h"

namespace rotafab::geometry {

struct StabilityOptions {
  int up = 1;                     // the axis that points up: 0 x, 1 y, 2 z
  double gramsPerSquareInch = 0;  // of the sheet; 0: not known (the centre of mass is the area's)
  double gramsPerFastener = 0;
};

struct Stability {
  std::optional<double> massKg;  // none when the sheet's areal density is not known
  Point3 centerOfMass = Point3::Zero();
  // The footprint's corners at the height of the ground, counter-clockwise
  // seen from above; one or two points when it rests on a point or a line.
  std::vector<Point3> footprint;
  bool stands = false;
  // Inches from the centre of mass, straight down on the ground, to the
  // footprint's outline: positive inside, negative outside (then it tips).
  double margin = 0;
  std::vector<Point3> hangPoints;  // two when it does not stand, none when it does
};

// Points within this share of the structure's height of its lowest point
// rest on the ground too (the board bends, and a structure settles on its
// lowest panels), and never less than kGroundToleranceInches.
constexpr double kGroundToleranceShare = 0.01;
constexpr double kGroundToleranceInches = 1.0 / 32;

// A structure that does not stand but whose centre of mass is within this of
// its footprint's outline (inches) balances on it: a touch tips it.
constexpr double kBalanceInches = 0.005;

// Throws std::invalid_argument for an empty structure or an axis not 0-2.
Stability structureStability(const Structure& structure, const StabilityOptions& options);

}  // namespace rotafab::geometry
