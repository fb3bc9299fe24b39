#include "jobs/SheetPlanner.h"

#include <cctype>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "core/Polygon2.h"
#include "jobs/DxfWriter.h"
#include "jobs/RowLayout.h"
#include "jobs/SvgWriter.h"
#include "toolpath/AtomicFile.h"
#include "toolpath/EpsWriter.h"

namespace rotafab::jobs {

Point2 onSheet(const PlannedPart& placement, const Point2& local) {
  return rotatedPoint(local, placement.rotation) + Point2(placement.x, placement.y);
}

double roomOnTheBed(const std::vector<Part>& parts, const profiles::MachineProfile& machine, double kerf) {
  const double width = machine.bed.width - 2 * machine.bed.margin - kerf;
  const double height = machine.bed.height - 2 * machine.bed.margin - kerf;
  double room = std::numeric_limits<double>::infinity();
  for (const Part& part : parts) {
    double best = 0;
    for (double rotation : part.rotations) {
      const auto [low, high] = rotatedBox(part.outline, rotation);
      const Point2 size = high - low;
      best = std::max(best, std::min(width / size.x(), height / size.y()));
    }
    room = std::min(room, best);
  }
  return room;
}

SheetPlan planSheets(const std::vector<Part>& parts, const profiles::MachineProfile& machine,
                     const PlanOptions& options, const core::WorkContext& context) {
  const profiles::Bed& bed = machine.bed;
  std::vector<Part> cut;
  cut.reserve(parts.size());
  for (const Part& part : parts) {
    context.check();
    cut.push_back(compensateKerf(part, options.kerf));
  }

  std::vector<NestingPart> nestingParts;
  for (const Part& part : cut) nestingParts.push_back({part.name, part.outline, part.rotations, part.order});
  NestingOptions nesting;
  nesting.width = bed.width - 2 * bed.margin;
  nesting.height = bed.height - 2 * bed.margin;
  nesting.spacing = options.spacing >= 0 ? options.spacing : 1.0 / 16 + options.kerf;
  nesting.seconds = options.seconds;
  nesting.evaluations = options.evaluations;
  nesting.order = options.order;
  nesting.window = options.window;
  nesting.seed = options.seed;
  nesting.anyAngle = true;
  NestingResult nested = options.rows ? rowLayout(nestingParts, nesting) : nest(nestingParts, nesting, context);

  SheetPlan plan;
  for (size_t i = 0; i < nested.placements.size(); ++i) {
    const PartPlacement& p = nested.placements[i];
    plan.parts.push_back({p.part, p.sheet, p.x + bed.margin, p.y + bed.margin, p.rotation, static_cast<int>(i),
                          static_cast<int>(i) - parts[p.part].order});
  }
  plan.stopped = nested.stopped;
  plan.inRowsNote = inRowsNote(nested);
  for (const Part& part : parts) plan.partArea += std::abs(polygonArea(part.outline));
  plan.utilization = plan.partArea / (nested.sheets * nesting.width * nesting.height);

  for (int s = 1; s <= nested.sheets; ++s) {
    SheetDrawing sheet;
    sheet.index = s;
    sheet.sheetCount = nested.sheets;
    sheet.width = bed.width;
    sheet.height = bed.height;
    sheet.margin = bed.margin;
    sheet.title =
        fmt::format("{}{}sheet {} of {}", options.title, options.title.empty() ? "" : " - ", s, nested.sheets);
    for (profiles::Operation operation : profiles::kAllOperations)
      sheet.colours[operation] = machine.settingFor(operation).rgb;
    // The material's edge (not cut), then per operation in cutting order.
    sheet.paths.push_back(
        {Operation::Outline, {{0, 0}, {bed.width, 0}, {bed.width, bed.height}, {0, bed.height}}, true});
    auto add = [&](Operation operation, const std::vector<Polyline2>& strokes, const PlannedPart& placed, bool closed) {
      for (const Polyline2& stroke : strokes) {
        if (stroke.size() < 2) continue;
        DrawnPath path{operation, {}, closed, partId(parts[placed.part].name)};
        path.points.reserve(stroke.size());
        for (const Point2& p : stroke) path.points.push_back(onSheet(placed, p));
        path.points = core::simplifiedLine(path.points, kSheetSimplification, closed);
        sheet.paths.push_back(std::move(path));
      }
    };
    for (Operation stage : {Operation::Etch, Operation::Score}) {
      for (const PlannedPart& placed : plan.parts) {
        if (placed.sheet != s) continue;
        add(stage, stage == Operation::Etch ? cut[placed.part].etch : cut[placed.part].score, placed, false);
      }
    }
    for (const PlannedPart& placed : plan.parts) {
      if (placed.sheet != s) continue;
      add(Operation::Cut, cut[placed.part].holes, placed, true);
      for (const Circle& circle : cut[placed.part].circles) {
        sheet.paths.push_back(circlePath(Operation::Cut, {onSheet(placed, circle.centre), circle.radius},
                                         partId(parts[placed.part].name)));
      }
    }
    for (const PlannedPart& placed : plan.parts)
      if (placed.sheet == s) add(Operation::Cut, {cut[placed.part].outline}, placed, true);
    plan.sheets.push_back(std::move(sheet));
  }
  return plan;
}

std::string partId(const std::string& name) {
  std::string id;
  for (char c : name) id += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
  return id;
}

std::string previewFile(int sheet) { return fmt::format("sheet-{:03}.preview.svg", sheet); }

SheetFormats defaultFormats(const profiles::MachineProfile& machine) {
  SheetFormats formats;
  for (const std::string& format : machine.formats) {
    formats.eps = formats.eps || format == "eps";
    formats.svg = formats.svg || format == "svg";
    formats.dxf = formats.dxf || format == "dxf";
  }
  return formats;
}

SheetFormats formatsOf(const std::string& list) {
  SheetFormats formats{false, false, false};
  size_t start = 0;
  while (start <= list.size()) {
    const size_t end = std::min(list.find(',', start), list.size());
    const std::string format = list.substr(start, end - start);
    if (format == "eps") {
      formats.eps = true;
    } else if (format == "svg") {
      formats.svg = true;
    } else if (format == "dxf") {
      formats.dxf = true;
    } else {
      throw std::invalid_argument(
          fmt::format("'{}' is not a sheet format: give eps, svg or dxf, separated by commas", format));
    }
    start = end + 1;
  }
  return formats;
}

std::vector<std::vector<std::string>> writeSheets(const SheetPlan& plan, const SheetFormats& formats,
                                                  const std::filesystem::path& folder, const core::WorkContext& context,
                                                  core::LengthUnit shownIn) {
  std::filesystem::create_directories(folder);
  std::vector<std::vector<std::string>> files(plan.sheets.size());
  // The sheets shared out among the threads: the bunny's 31 sheets are 170 MB
  // of text, and formatting them, not the disk, takes the time.
  context.parallelFor(plan.sheets.size(), [&](size_t s) {
    const SheetDrawing& sheet = plan.sheets[s];
    const std::string stem = fmt::format("sheet-{:03}", sheet.index);
    const auto write = [&](bool wanted, const std::string& name, const auto& writer) {
      if (!wanted) return;
      writeFileAtomically(folder / name, [&](std::ostream& out) { writer(sheet, out); });
      files[s].push_back(name);
      context.check();
    };
    write(formats.eps, stem + ".eps", writeEps);
    write(formats.svg, stem + ".svg", writeSvg);
    write(formats.dxf, stem + ".dxf", writeDxf);
    writeFileAtomically(folder / previewFile(sheet.index),
                        [&](std::ostream& out) { writeSvgPreview(sheet, out, shownIn); });
  });
  return files;
}

std::vector<Part> structureParts(const geometry::Structure& structure) {
  std::vector<Part> parts;
  const auto add = [&](const std::string& name, int order, const Polygon2& outline,
                       const std::vector<geometry::PanelHole>& holes, const std::vector<geometry::PanelLabel>& labels,
                       const std::vector<Polyline2>& scores) {
    Part part;
    part.name = name;
    part.order = order;
    part.outline = outline;
    for (const geometry::PanelHole& hole : holes) part.circles.push_back({hole.xy, hole.diameter / 2});
    for (const geometry::PanelLabel& label : labels) {
      part.etch.insert(part.etch.end(), label.strokes.begin(), label.strokes.end());
    }
    part.score = scores;
    parts.push_back(std::move(part));
  };
  // One running order: a panel, then its pieces, then the next panel (so
  // that pieces do not push later panels out of the planner's window).
  for (const auto& [i, k] : partOwners(structure)) {
    const geometry::Panel& panel = structure.panels[i];
    if (k < 0) {
      add(fmt::format("panel {}", panel.id), static_cast<int>(parts.size()), panel.outline, panel.holes, panel.labels,
          panel.scores);
    } else {
      const geometry::PanelPiece& piece = panel.pieces[k];
      add("piece " + piece.name, static_cast<int>(parts.size()), piece.outline, piece.holes, piece.labels, {});
    }
  }
  return parts;
}

std::vector<std::pair<int, int>> partOwners(const geometry::Structure& structure) {
  std::vector<std::pair<int, int>> owners;
  for (size_t i = 0; i < structure.panels.size(); ++i) {
    owners.emplace_back(static_cast<int>(i), -1);
    for (size_t k = 0; k < structure.panels[i].pieces.size(); ++k) {
      owners.emplace_back(static_cast<int>(i), static_cast<int>(k));
    }
  }
  return owners;
}

}  // namespace rotafab::jobs
