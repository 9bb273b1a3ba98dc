// Fuzz target: mesh files (STL ascii/binary and OBJ through assimp, PLY and OFF through our own
// readers), our loader's welding and our validation (load_mesh). The first byte picks the file
// name's extension (which selects the reader: 'o' .obj, 'p' .ply, 'f' .off, anything else .stl);
// the rest is the file, written to a per-process file under /dev/shm (the readers take paths). Each
// input is loaded three times: as a shape (closed solid required, self-intersections checked), as a
// shape whose holes and orientation may be repaired, and as a wall (open surfaces allowed), and
// what an accepted mesh promises is checked.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "clumpkit/mesh_io/load_mesh.hpp"
#include "fuzz_util.hpp"

namespace {

namespace fs = std::filesystem;

fs::path scratch_file(const char* ext) {
  const fs::path dir =
      fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
  return dir / ("clumpkit_fuzz_mesh_" + std::to_string(::getpid()) + ext);
}

void check_mesh(const clumpkit::TriangleMesh& m, const clumpkit::MeshReport& r, bool closed) {
  CLUMPKIT_FUZZ_CHECK(!m.triangles.empty(), "accepted a mesh without triangles");
  for (const Eigen::Vector3i& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      CLUMPKIT_FUZZ_CHECK(t[k] >= 0 && static_cast<std::size_t>(t[k]) < m.vertices.size(),
                          "triangle index out of range");
  CLUMPKIT_FUZZ_CHECK(r.triangles == m.triangles.size(), "report triangle count");
  for (const Eigen::Vector3d& v : m.vertices)
    CLUMPKIT_FUZZ_CHECK(v.allFinite(), "non-finite vertex in an accepted mesh");
  if (!closed) return;
  CLUMPKIT_FUZZ_CHECK(r.closed_solid(), "accepted a mesh that is not a closed solid");
  CLUMPKIT_FUZZ_CHECK(std::isfinite(r.signed_volume) && r.signed_volume >= 0.0,
                      "accepted solid is not outward");
  CLUMPKIT_FUZZ_CHECK(std::isfinite(r.area) && r.area >= 0.0, "area");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace clumpkit;
  if (size == 0) return 0;
  const char* ext = data[0] == 'o'   ? ".obj"
                    : data[0] == 'p' ? ".ply"
                    : data[0] == 'f' ? ".off"
                                     : ".stl";
  const fs::path path = scratch_file(ext);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  // As a shape, as a shape with its holes and orientation repaired on request, and as a wall.
  for (const int mode : {0, 1, 2}) {
    const bool closed = mode < 2;
    fuzz::input_errors_only([&] {
      MeshLoadOptions o;
      o.scale = 0.001;
      o.require_closed = closed;
      o.check_self_intersections = closed;
      o.repair_orientation = o.repair_holes = mode == 1;
      MeshReport r;
      const TriangleMesh m = load_mesh(path, o, &r);
      check_mesh(m, r, closed);
    });
  }
  std::error_code ec;
  fs::remove(path, ec);
  return 0;
}
