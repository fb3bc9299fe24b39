#include "jobs/Manifest.h"
#include "jobs/ManifestSteps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>

#include "core/UserError.h"
#include "geometry/WeaveStructure.h"
#include "jobs/JobCost.h"
#include "jobs/SvgWriter.h"
#include "toolpath/JsonErrors.h"

namespace rotafab::jobs {

std::string manifestHtml(const nlohmann::ordered_json& manifest, const std::filesystem::path& folder,
                         std::optional<core::LengthUnit> unit) {
  try {
    std::string html = fmt::format(R"(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>Assembly manifest: {0}</title>
<style>
body {{ font-family: sans-serif; margin: 2em; }}
table {{ border-collapse: collapse; }}
td, th {{ border: 1px solid #999; padding: 0.2em 0.6em; text-align: left; vertical-align: top; }}
section.sheet {{ break-before: page; }}
section.sheet svg {{ width: 100%; height: auto; border: 1px solid #ccc; }}
section.sheet .cutfile svg path {{ vector-effect: non-scaling-stroke; stroke-width: 1px; }}
section.sheet .cutfile svg #etch path {{ stroke: #a0522d; }}
@media print {{ body {{ margin: 0; }} }}
</style>
</head>
<body>
<h1>Assembly manifest</h1>
<p>{0}. {1}</p>
<table>
<tr><th>step</th><th>panel</th><th>sheet</th><th>joins</th><th>fasteners</th></tr>
)",
                                   xmlText(headline(manifest)), xmlText(howToJoin(manifest)));
    for (const std::string& note : buildNotes(manifest, unit.value_or(displayUnitOf(manifest))))
      html += fmt::format("<p>{}</p>\n", xmlText(note));
    int total = 0;
    for (const StepLine& step : stepLines(manifest)) {
      total += step.fasteners;
      html += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n", step.panel, step.panel,
                          step.sheet, xmlText(step.joins), step.fasteners);
    }
    html += fmt::format("</table>\n<p>{} fastener{} in all.</p>\n", total, total == 1 ? "" : "s");
    for (const auto& sheet : manifest.at("sheets")) {
      // The preview, made for people; else (a manifest from before previews) the cut file, restyled.
      std::string svgFile;
      for (const auto& file : sheet.at("files")) {
        const auto name = file.get<std::string>();
        if (name.ends_with(".svg")) svgFile = name;
      }
      const bool preview = sheet.contains("preview");
      if (preview) svgFile = sheet.at("preview").get<std::string>();
      std::string panels;
      for (const auto& id : sheet.at("panels")) panels += (panels.empty() ? "" : ", ") + std::to_string(id.get<int>());
      html += fmt::format("<section class=\"sheet\">\n<h2>Sheet {}</h2>\n<p>Panels, in cutting order: {}</p>\n",
                          sheet.at("index").get<int>(), panels);
      if (!svgFile.empty()) {
        std::ifstream in(folder / svgFile);
        if (!in) throw std::invalid_argument(fmt::format("{}: cannot read it", (folder / svgFile).string()));
        std::string svg{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
        if (svg.starts_with("<?xml")) svg.erase(0, svg.find('\n') + 1);  // no declaration inside HTML
        html += fmt::format("<div class=\"{}\">\n{}</div>\n", preview ? "preview" : "cutfile", svg);
      }
      html += "</section>\n";
    }
    html += "</body>\n</html>\n";
    return html;
  } catch (const nlohmann::json::exception& error) {
    throw std::invalid_argument(
        fmt::format("the manifest is not manifest.json version 1 (docs/CONTRACT.md): {}", jsonErrorText(error)));
  }
}

}  // namespace rotafab::jobs
