#pragma once
// A quick layout for previews and very large jobs: parts in rows by their
// bounding boxes, in assembly order (so the cutting order is the assembly
// order), rows bottom to top, sheets one after another. Linear in the parts,
// against the seconds per part of true-shape nesting (nest()); it uses more
// sheets, as boxes waste the room between concave parts.

#include "jobs/Nesting.h"

namespace rotafab::jobs {

// Beds only (not strip mode). For each part, the allowed rotation whose box
// is lowest, then narrowest. Throws std::invalid_argument naming a part that
// fits the usable area in no allowed rotation.
NestingResult rowLayout(const std::vector<NestingPart>& parts, const NestingOptions& options);

}  // namespace rotafab::jobs
