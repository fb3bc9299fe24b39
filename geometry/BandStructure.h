#pragma once
// A band decomposition structure, end to end in geometry (dissertation ch. V):
// vertex bands (V.1-V.2), developable edge bands (V.3), unfolded panels
// (V.4), fastener holes, labels and flood-fill numbering (V.5). The output is
// one Panel per input face, flat and ready for the planner, in assembly
// order, and the 3D surface of each for rendering.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "geometry/PanelLabels.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

using Polyline2 = std::vector<Point2>;

struct PanelHole {
  int edge = 0;  // the edge number of the band it fastens (1-based)
  Point2 xy;     // panel frame, inches
  double diameter = 0;
};

struct PanelLabel {
  std::string text;  // as etched ("6." for 6)
  int edge = 0;      // the edge number for an edge label, 0 for the panel number
  std::string role;  // "edge" or "panel"
  TextBox box;
  std::vector<Polyline2> strokes;
};

// A band cut off its panel because the panel would overlap itself when
// unfolded (V.4): the band and a tab that lies over the panel's vertex band,
// fastened to it through one extra hole. Cut as a part of its own.
struct PanelPiece {
  std::string name;                // "17a": its panel's number and a letter
  int edge = 0;                    // the edge number of its band
  Polyline2 outline;               // in the panel's frame, where it lies on the panel; counter-clockwise
  std::vector<PanelHole> holes;    // the band's, then the tab's (edge 0)
  std::vector<PanelLabel> labels;  // the edge number on the band, the name on the tab
  double area = 0;                 // of the band in 3D (the tab doubles the vertex band)
};

struct Panel {
  int id = 0;                    // flood-fill number, 1-based: the assembly order
  int face = 0;                  // the input face (its index in the file)
  Polyline2 outline;             // the cut contour, counter-clockwise, not closed
  std::vector<PanelHole> holes;  // a tab's fastener has edge 0
  std::vector<PanelLabel> labels;
  std::vector<PanelPiece> pieces;            // bands cut off, each fastened back by a tab
  std::vector<Polyline2> scores;             // fold lines between the vertex band and its bands (--score-folds)
  std::vector<int> neighbors;                // panel ids across its bands, in the order of its sides
  std::vector<int> edges;                    // the edge numbers of its bands, in the same order
  double area = 0;                           // the 3D surface area, square inches
  std::vector<std::vector<Point3>> surface;  // 3D polygons: the vertex band, then the bands' triangles
};

struct BandOptions {
  std::optional<double> tension;  // eq. 5.2's a for every dual face; Doo-Sabin per face when empty
  int samples = 8;                // segments along each band
  double fastener = 0.125;        // hole diameter, inches
  std::optional<int> start;       // flood-fill start face (file index); the lowest face when empty
  int up = 1;                     // the vertical axis for "lowest": 0 x, 1 y, 2 z
  bool scoreFolds = false;
  std::function<void(const std::string&)> progress;
};

struct BandStructure {
  std::vector<Panel> panels;  // in flood-fill order: panels[i].id == i + 1
  int interiorEdges = 0;
  int fasteners = 0;                  // one per hole pair, and one per piece's tab
  std::vector<std::string> warnings;  // one line each (labels that did not fit, ...)
};

// The mesh must be usable (analyzeMesh), already at construction size
// (inches). Throws InvalidMeshError or std::invalid_argument with one line
// naming what cannot be built.
BandStructure buildBandStructure(const PolygonMesh& mesh, const BandOptions& options);

// Construction size (SPEC "Units and scale"): the factor that makes the mean
// edge length 2 in, or the largest bounding-box side `size`, or `scale` itself.
double constructionScale(const PolygonMesh& mesh, std::optional<double> size, std::optional<double> scale);

}  // namespace rotafab::geometry
