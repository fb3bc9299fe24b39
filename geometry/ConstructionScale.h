#pragma once
// The construction size of a structure (docs/CONTRACT.md, "Units and scale"): the
// factor that makes the mesh's mean edge 2 in, or its largest bounding-box
// side a given length, or a factor given as it is.

#include <optional>

#include "geometry/Parameters.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// The mean edge's length at the default scale.
constexpr double kMeanEdgeInches = 2.0;

// Inches per mesh unit. Throws ParameterError (Size) when the mesh has no
// extent to scale to a size, std::invalid_argument when it has no edge of
// positive length.
double constructionScale(const PolygonMesh& mesh, std::optional<double> size, std::optional<double> scale,
                         const ParameterNames& names = parameterInWords);

}  // namespace rotafab::geometry
