#include "geometry/Parameters.h"

namespace rotafab::geometry {

std::string parameterInWords(Parameter parameter) {
  switch (parameter) {
    case Parameter::Structure:
      return "structure";
    case Parameter::Holes:
      return "holes";
    case Parameter::Repair:
      return "repair";
    case Parameter::MergeCoplanar:
      return "coplanar merge angle";
    case Parameter::Panels:
      return "panel count";
    case Parameter::Size:
      return "structure size";
    case Parameter::Scale:
      return "scale";
    case Parameter::Fastener:
      return "fastener diameter";
    case Parameter::Start:
      return "start face";
    case Parameter::Width:
      return "ribbon width";
    case Parameter::Offset:
      return "ribbon offset";
    case Parameter::KeepFaces:
      return "faces kept as drawn";
    case Parameter::GlueNarrow:
      return "narrow bands glued";
  }
  return "parameter";
}

}  // namespace rotafab::geometry
