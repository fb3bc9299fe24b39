#pragma once
// Clipper's Boolean operations and areas, for tests that compare regions.

#include <clipper.hpp>

namespace rotafab::test {

// The paths' signed area: outer contours count positive, holes negative.
inline double areaOf(const ClipperLib::Paths& paths) {
  double area = 0;
  for (const ClipperLib::Path& p : paths) area += ClipperLib::Area(p);
  return area;
}

inline ClipperLib::Paths boolean(ClipperLib::ClipType type, const ClipperLib::Paths& a, const ClipperLib::Paths& b) {
  ClipperLib::Clipper clipper;
  clipper.AddPaths(a, ClipperLib::ptSubject, true);
  clipper.AddPaths(b, ClipperLib::ptClip, true);
  ClipperLib::Paths out;
  clipper.Execute(type, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

}  // namespace rotafab::test
