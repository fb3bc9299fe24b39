#pragma once
// The parameters of a build that messages name: geometry says which one an
// error or a piece of advice is about, and the caller says what to call it
// (the command line by its flag, "--fastener"; a daemon by its field).

#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "core/LengthUnit.h"

namespace rotafab::geometry {

enum class Parameter {
  Structure,      // band or weave
  Holes,          // what to do with an open mesh's holes: keep, fill, refuse
  Repair,         // whether to repair a broken mesh (MeshRepair.h) or refuse it
  MergeCoplanar,  // the angle within which adjacent faces are merged into one (CoplanarMerge.h)
  Panels,         // the panel count the mesh is remeshed for (Remeshing.h)
  Size,           // the largest side of the structure
  Scale,          // inches per mesh unit
  Fastener,       // the fastener hole's diameter
  Start,          // the flood fill's first face
  Width,          // a woven ribbon's share of its edge region across it
  Offset,         // how far a woven ribbon stands over or under the surface
  KeepFaces,      // keep every face as drawn: no short edge collapsed to give a band room (MeshMending.h)
  GlueNarrow,     // glue the bands that have no room for a fastener, rather than refuse
};

// In words: "structure", "holes", "repair", "coplanar merge angle", "panel count", "structure size", "scale", "fastener
// diameter", "start face", "ribbon width", "ribbon offset", "faces kept as drawn", "narrow bands glued".
std::string parameterInWords(Parameter parameter);

// The caller's words for messages: how they name a parameter (`names(Parameter::Size)`),
// and the unit they give lengths in ("a 3.18 mm fastener").
struct ParameterNames {
  ParameterNames() = default;
  template <typename Naming>
  requires std::is_invocable_r_v<std::string, Naming, Parameter> ParameterNames(
      Naming naming, core::LengthUnit unit = {})  // NOLINT: a naming function is its names
      : name(std::move(naming)), unit(unit) {}
  std::string operator()(Parameter parameter) const { return name(parameter); }

  std::function<std::string(Parameter)> name = parameterInWords;
  core::LengthUnit unit;
};

// A parameter's value that cannot be built with; the message names it as
// the caller's ParameterNames do: "fastener diameter: the hole diameter must be positive".
class ParameterError : public std::invalid_argument {
 public:
  ParameterError(Parameter parameter, const std::string& message)
      : std::invalid_argument(message), parameter(parameter) {}
  Parameter parameter;
};

}  // namespace rotafab::geometry
