#include "clumpkit/mesh_io/write_mesh.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "clumpkit/core/atomic_file.hpp"

namespace clumpkit {

namespace {
template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // STL is little-endian, as is every target we build for
  out.append(bytes, sizeof(T));
}
}  // namespace

void write_stl(const TriangleMesh& mesh, const std::filesystem::path& path, double scale) {
  std::string out(80, ' ');
  const std::string header = "clumpkit binary STL";
  out.replace(0, header.size(), header);
  put(out, static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] * scale, b = mesh.vertices[t[1]] * scale,
                          c = mesh.vertices[t[2]] * scale;
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() > 0) n.normalize();
    for (const Eigen::Vector3d& p : {n, a, b, c})
      for (int k = 0; k < 3; ++k) put(out, static_cast<float>(p[k]));
    put(out, std::uint16_t{0});
  }
  write_file_atomic(path, out);
}

void write_obj(const TriangleMesh& mesh, const std::filesystem::path& path, double scale) {
  std::string out = "# clumpkit OBJ\n";
  for (const Eigen::Vector3d& v : mesh.vertices)
    out += fmt::format("v {:.17g} {:.17g} {:.17g}\n", v[0] * scale, v[1] * scale, v[2] * scale);
  for (const Eigen::Vector3i& t : mesh.triangles)
    out += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  write_file_atomic(path, out);
}

}  // namespace clumpkit
