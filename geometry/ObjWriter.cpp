#include "geometry/ObjWriter.h"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "core/Decimal.h"

namespace rotafab::geometry {

void writeObj(std::ostream& out, const PolygonMesh& mesh, std::string_view comment, const std::vector<ObjGroup>& groups,
              std::optional<int> decimals) {
  fmt::memory_buffer buffer;
  // Written a few megabytes at a time: a large structure's text need not be
  // held whole.
  constexpr size_t kFlushAt = size_t{4} << 20;
  const auto flush = [&] {
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    buffer.clear();
  };
  if (!comment.empty()) fmt::format_to(std::back_inserter(buffer), "# {}\n", comment);
  for (const Point3& p : mesh.positions) {
    if (decimals) {
      buffer.push_back('v');
      for (int axis = 0; axis < 3; ++axis) {
        buffer.push_back(' ');
        core::appendUnits(buffer, core::unitsOf(p[axis], *decimals), *decimals);
      }
      buffer.push_back('\n');
    } else {
      fmt::format_to(std::back_inserter(buffer), "v {} {} {}\n", p.x(), p.y(), p.z());
    }
    if (buffer.size() >= kFlushAt) flush();
  }
  auto group = groups.begin();
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (; group != groups.end() && group->firstFace <= f; ++group) {
      fmt::format_to(std::back_inserter(buffer), "g {}\n", group->name);
    }
    buffer.push_back('f');
    for (int v : face) {
      buffer.push_back(' ');
      core::appendUnits(buffer, v + 1, 0);
    }
    buffer.push_back('\n');
    if (buffer.size() >= kFlushAt) flush();
  }
  flush();
}

}  // namespace rotafab::geometry
