#pragma once
// A baseline for the bin-mode nesting benchmark: the same
// parts through Debian's libnest2d 5.0 (no-fit-polygon placer, first-fit
// selection), so that our nester's sheet counts can be read against a public
// library's. libnest2d's no-fit polygons are only correct for convex shapes,
// so every part is replaced by its convex hull before libnest2d sees it: the
// figures are those of convex-hull nesting, which wastes the parts' concavities
// that our nester interlocks.
//
// libnest2d's own result is not trusted: every hull, moved by the translation
// and rotation libnest2d reports, is checked to lie in the usable area and to
// keep the spacing from every other hull on its sheet (hence the true outlines
// do too), and every part must have been given a sheet. The layout is
// deterministic (a serial search, no time budget); only `seconds` varies.

#include <string>
#include <vector>

#include "jobs/Nesting.h"

namespace rotafab::bench {

struct Libnest2dResult {
  int sheets = 0;                 // bins libnest2d opened
  std::vector<double> sheetArea;  // true (not hull) part area on each sheet, sq in
  double seconds = 0;             // hulls and libnest2d's nesting; not the check afterwards
  bool valid = true;              // false when libnest2d threw or its layout failed the check
  std::string problem;            // the first problem, one line; empty when valid
};

// Bins of options.width x options.height, options.spacing between hulls; strip
// mode is not supported (valid = false). libnest2d takes one set of rotations
// for all parts: the rotations every part allows are used (valid = false when
// none is common). Never throws for bad input or a libnest2d failure: they are
// reported in `problem`.
Libnest2dResult nestWithLibnest2d(const std::vector<rotafab::jobs::NestingPart>& parts,
                                  const rotafab::jobs::NestingOptions& options);

}  // namespace rotafab::bench
