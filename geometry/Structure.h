#pragma once
// What a structure builder gives the planner and the manifest, whatever the
// structure (band decomposition, dissertation ch. V; plain weave, ch. IV):
// flat panels ready to cut, in assembly order, each with its outline, holes
// and labels, where it comes from, the pieces cut off it and the panels it
// joins; the assembly steps; the fasteners; warnings. Lengths in inches,
// panel coordinates in the panel's own frame.

#include <functional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "core/Polygon2.h"
#include "core/WorkContext.h"
#include "geometry/PanelLabels.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

using Polyline2 = std::vector<Point2>;

enum class StructureKind { Band, Weave };
// The names in manifest.json's "structure" (docs/CONTRACT.md,
// "manifest.json (version 1)"): "band", "weave".
std::string_view structureName(StructureKind kind);

// What a label says (`labels[].role`, docs/CONTRACT.md,
// "manifest.json (version 1)"): an edge number, the panel's number, the
// neighbouring edge's number (a woven panel's underlined one), the edge of a
// woven panel's up or down crossing; and the name of a piece cut off a panel
// (ours, on the piece's tab).
enum class LabelRole { Edge, Panel, Neighbor, Up, Down, Piece };
// "edge", "panel", "neighbor", "up", "down", "piece".
std::string_view roleName(LabelRole role);

struct PanelHole {
  int edge = 0;  // the edge number it fastens (1-based); 0 for a piece's tab
  Point2 xy;     // panel frame
  double diameter = 0;
};

struct PanelLabel {
  std::string text;  // as etched ("6." for 6)
  int edge = 0;      // the edge number it names; 0 for the panel's own number and a piece's name
  LabelRole role = LabelRole::Edge;
  TextBox box;
  std::vector<Polyline2> strokes;
};

// Where a panel comes from (`source`, docs/CONTRACT.md,
// "manifest.json (version 1)"): a band panel from an input face (its index in
// the file) or from a face capping a hole (`cap`, no face); a woven panel from
// the edge of its up crossing and its cycle.
struct PanelSource {
  int face = -1;
  bool cap = false;
  int edge = -1;
  int cycle = -1;
};

// A part cut off its panel (a band that would make the panel overlap
// itself, V.4), cut as a part of its own and fastened back to the panel.
// How a piece cut off a panel is held: by a tab over the panel's vertex
// band, with one fastener of its own (the whole band cut off), or by the
// other copy of its band, through that band's holes (the far half of a band
// cut across its middle), or by a tab glued, with no room for a hole.
enum class PieceFastening { Tab, Band, Glue };

struct PanelPiece {
  std::string name;   // "17a": its panel's number and a letter
  int edge = 0;       // the edge number of its band
  Polyline2 outline;  // in the panel's frame, where it lies on the panel; counter-clockwise
  std::vector<PanelHole> holes;
  std::vector<PanelLabel> labels;
  double area = 0;  // in 3D
  PieceFastening fastening = PieceFastening::Tab;
};

std::string_view fasteningName(PieceFastening fastening);  // "tab", "band", "glue"

// A neighbouring panel, and the edge number along which the two are joined.
struct PanelJoin {
  int panel = 0;  // its id
  int edge = 0;
};

struct Panel {
  int id = 0;  // 1-based: the assembly order
  PanelSource source;
  Polyline2 outline;  // the cut contour, counter-clockwise, not closed
  std::vector<PanelHole> holes;
  std::vector<PanelLabel> labels;
  std::vector<PanelPiece> pieces;
  std::vector<Polyline2> scores;             // fold lines to score
  std::vector<PanelJoin> joins;              // in the order of its sides
  double area = 0;                           // the 3D surface area (its pieces' apart), square inches
  std::vector<std::vector<Point3>> surface;  // 3D polygons, for rendering
};

// One assembly step: a panel, the pieces to fasten to it first, and the
// panels placed before it that it joins, with the fasteners of each join.
struct AssemblyJoin {
  int panel = 0, edge = 0, fasteners = 0;
  std::vector<std::string> pieces;  // the halves of the edge's band cut across, fastened with it
};
struct AssemblyStep {
  int panel = 0;
  std::vector<std::string> pieces;  // held by a tab: one fastener each
  std::vector<AssemblyJoin> joins;
  std::vector<std::string> gluedPieces;  // held by a tab glued
};

struct Structure {
  StructureKind kind = StructureKind::Band;
  std::vector<Panel> panels;  // in assembly order: panels[i].id == i + 1
  std::vector<AssemblyStep> steps;
  int edges = 0;                      // edge numbers run 1..edges
  int fasteners = 0;                  // one per pair of holes that meet, one per piece's tab
  std::vector<int> glued;             // edge numbers of the bands with no room for a hole, to be glued
  std::vector<std::string> warnings;  // one line each (labels that did not fit, ...)
  std::vector<std::string> notes;     // one line each: what was chosen for the user (ribbons narrowed, ...)
};

// The steps of building panel by panel in id order (the flood fill's, V.5,
// or a weave's cycle by cycle): each panel joined to those before it; a
// join's fasteners are the holes of its edge on the panel and its pieces,
// and a band's half cut off either panel goes on with the join of its edge.
std::vector<AssemblyStep> stepsInPanelOrder(const std::vector<Panel>& panels);

// Each panel turned in its own frame so that its outline's least-area
// bounding box (Freeman and Shapira, CACM 1975: one of its sides lies along
// a side of the convex hull) is axis-aligned, its longer side along x: the
// frame a nester's quarter turns and a row of boxes waste least room in (a
// woven panel lay at any angle, its box twice its least on average; a band
// panel's own frame packed as well or better). Its outline, holes, labels,
// pieces and scores all turn together.
void layPanelsAlongTheirLeastBoxes(std::vector<Panel>& panels, const core::WorkContext& context);

// The panels' 3D surfaces as one mesh, polygon by polygon, each panel's
// polygons sharing their common corners (panels share none).
PolygonMesh surfaceMesh(const Structure& structure);

// structure.obj: surfaceMesh() as Wavefront OBJ, a group "g panel-17" per
// panel, coordinates to `decimals`, written a panel at a time (a 50,000-panel
// structure's mesh is never held whole). `comment` is its first line.
void writeStructureObj(std::ostream& out, const Structure& structure, std::string_view comment, int decimals);

// A structure built at the smallest size, from the mesh's, at which every
// fastener hole has room (FastenerHoles.h, kLeastClearance): when `build`
// throws NoRoomForHoleError, the mesh is scaled by what the places without
// room ask and built again: kGrowAttempts times, and on while each attempt
// leaves fewer places without room, at most kMostGrowAttempts times. (A
// band's lengths all scale with the mesh; a weave's offset and the widths
// it narrows to do not, so the scale its crossings ask for falls a little
// short at the next size: CGAL's knot2 needed 1.39, 1.12, then 1.03 more.)
// `mesh` is left at the size built; `grown`
// says how many times its size it became (1: as given). Throws what `build`
// does, the NoRoomForHoleError of the last attempt with the `scales` of the
// size given, as the first try found them. Progress: phase "geometry", step
// "larger, for the fasteners" before each new attempt.
struct GrownStructure {
  Structure structure;
  double grown = 1;
  int bandsWithoutRoom = 0;          // at the size given (bands, or a weave's crossings)
  std::vector<double> scalesNeeded;  // what each of them needed, times the size given
};
constexpr int kGrowAttempts = 3;
constexpr int kMostGrowAttempts = 6;
GrownStructure growUntilRoom(PolygonMesh& mesh, const std::function<Structure(const PolygonMesh&)>& build,
                             const core::WorkContext& context);

}  // namespace rotafab::geometry
