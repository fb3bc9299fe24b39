#include "geometry/io/ObjWriter.h"

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace rotafab::geometry {

void writeObj(std::ostream& out, const PolygonMesh& mesh, std::string_view comment,
              const std::vector<ObjGroup>& groups) {
  fmt::memory_buffer buffer;
  if (!comment.empty()) fmt::format_to(std::back_inserter(buffer), "# {}\n", comment);
  for (const Point3& p : mesh.positions)
    fmt::format_to(std::back_inserter(buffer), "v {} {} {}\n", p.x(), p.y(), p.z());
  auto group = groups.begin();
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (; group != groups.end() && group->firstFace <= f; ++group) {
      fmt::format_to(std::back_inserter(buffer), "g {}\n", group->name);
    }
    buffer.push_back('f');
    for (int v : face) fmt::format_to(std::back_inserter(buffer), " {}", v + 1);
    buffer.push_back('\n');
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

}  // namespace rotafab::geometry
