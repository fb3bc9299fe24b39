#pragma once
// A flat part to be cut: its outer contour, its inner cut
// contours (fastener holes), the open strokes to score and to etch (labels,
// already single-stroke polylines), an assembly order, and the rotations the
// nester may use. Design size, inches, in the part's own frame.

#include <string>
#include <vector>

#include "jobs/Nesting.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

using Polyline2 = std::vector<Point2>;

struct Part {
  std::string name;              // for messages and manifests: "panel 17"
  int order = 0;                 // assembly order, 0-based
  Polygon2 outline;              // outer contour
  std::vector<Polygon2> holes;   // inner contours, cut before the outline
  std::vector<Circle> circles;   // round holes (fasteners), cut with the holes
  std::vector<Polyline2> score;  // fold lines
  std::vector<Polyline2> etch;   // labels
  std::vector<double> rotations{0.0, 90.0, 180.0, 270.0};
};

// The polygon offset outwards (positive) or inwards (negative) by `distance`,
// with round corners: what a beam of that radius traces around it. Throws
// std::invalid_argument when an inward offset makes the polygon vanish.
Polygon2 offsetPolygon(const Polygon2& polygon, double distance);

// Kerf compensation: the beam removes kerf/2 on each side of its path, so
// the outer contour is cut kerf/2 outside the design and each hole kerf/2
// inside it (a circle's radius kerf/2 less); strokes stay on their centre
// lines. Throws std::invalid_argument naming the part when a hole is
// narrower than the kerf.
Part compensateKerf(const Part& part, double kerf);

}  // namespace rotafab::jobs
