#pragma once
// A picture of a nesting layout for people: every sheet (or the strip) with
// its parts, each titled with its name. Not a cutting file (see SvgWriter.h).

#include <string>
#include <vector>

#include "jobs/Nesting.h"

namespace rotafab::jobs {

// Sheets one above the other, in inches; `margin` shifts the usable area onto the bed.
std::string layoutSvg(const std::vector<NestingPart>& parts, const NestingResult& result, const NestingOptions& options,
                      double margin);

}  // namespace rotafab::jobs
